"""The offline planner's library of long-horizon goals, each 3 to 6 subtasks of verified skills.

A goal is data: the phrasings it answers to (for paraphrase matching), its objects and its
subtasks. Subtasks reuse the skills and success predicates of the atomic tasks (put on, put in,
press, arrange by position), so every goal is built from parts whose experts are measured.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from vcage.planning.schema import GoalMatch, Plan, PlanObject, PlanRelation, Predicate, Subtask


@dataclass(frozen=True)
class Goal:
    name: str
    phrasings: tuple[str, ...]
    objects: tuple[PlanObject, ...]
    subtasks: tuple[Subtask, ...]
    relations: tuple[PlanRelation, ...] = ()

    def plan(self, instruction: str, match: GoalMatch | None = None,
             objects: tuple[PlanObject, ...] | None = None) -> Plan:
        """The goal's plan labelled ``instruction`` (``objects``: the goal's objects with colours the
        instruction chose, same names and order)."""
        return Plan(instruction=instruction, goal=self.name,
                    objects=self.objects if objects is None else objects,
                    relations=self.relations, subtasks=self.subtasks, match=match)


def _obj(name: str, type_: str, color: str | None = None) -> PlanObject:
    return PlanObject(name=name, type=type_, color=color)


def put_on(obj: str, target: str, text: str, also: tuple[Predicate, ...] = ()) -> Subtask:
    """``obj`` on ``target`` and released; ``also``: what must still hold (e.g. what it carries)."""
    return Subtask(skill="pick_and_place", args={"obj": obj, "target": target}, description=text,
                   predicates=(Predicate(name="on", args=(obj, target)),
                               Predicate(name="released", args=(obj,)), *also))


def put_in(obj: str, target: str, text: str, also: tuple[Predicate, ...] = ()) -> Subtask:
    return Subtask(skill="pick_and_place", args={"obj": obj, "target": target}, description=text,
                   predicates=(Predicate(name="inside", args=(obj, target)),
                               Predicate(name="released", args=(obj,)), *also))


def holds(name: str, *args: str) -> Predicate:
    """A predicate a later subtask keeps checking (a stack that must survive being moved)."""
    return Predicate(name=name, args=args)


def press(obj: str, text: str, point: str | None = None) -> Subtask:
    args: dict[str, Any] = {"obj": obj} if point is None else {"obj": obj, "point": point}
    return Subtask(skill="press", args=args, description=text,
                   predicates=(Predicate(name="pressed", args=(obj,)),
                               Predicate(name="upright", args=(obj,))))


def open_drawer(obj: str, text: str) -> Subtask:
    return Subtask(skill="open_drawer", args={"obj": obj}, description=text,
                   predicates=(Predicate(name="opened", args=(obj,)),))


def close_drawer(obj: str, text: str) -> Subtask:
    return Subtask(skill="close_drawer", args={"obj": obj}, description=text,
                   predicates=(Predicate(name="closed", args=(obj,)),))


def turn_to_face(obj: str, text: str) -> Subtask:
    """``obj`` put back down where it stood, turned so that its functional face points at the robot."""
    return Subtask(skill="turn_to_face", args={"obj": obj}, description=text,
                   predicates=(Predicate(name="facing", args=(obj,)), Predicate(name="on_table", args=(obj,)),
                               Predicate(name="upright", args=(obj,))))


def hang(obj: str, target: str, text: str) -> Subtask:
    """``obj`` hung by its loop on ``target``'s hook, and let go."""
    return Subtask(skill="hang", args={"obj": obj, "target": target}, description=text,
                   predicates=(Predicate(name="hanging", args=(obj, target)),
                               Predicate(name="released", args=(obj,))))


def put_at(obj: str, xy: tuple[float, float], text: str, left_of: str | None = None) -> Subtask:
    preds = [Predicate(name="on_table", args=(obj,)), Predicate(name="released", args=(obj,))]
    if left_of is not None:
        preds.append(Predicate(name="left_of", args=(obj, left_of)))
    return Subtask(skill="pick_and_place", args={"obj": obj, "xy": list(xy)}, description=text,
                   predicates=tuple(preds))


ROW_X = 0.5  # where arranged objects are lined up (clear of the arm's home pose in the top view)

GOALS: tuple[Goal, ...] = (
    Goal("get_ready_for_work",
         ("get ready for work", "prepare my desk for the work day", "set up my workspace",
          "get my desk ready for the morning"),
         (_obj("phone", "phone"), _obj("stand", "phone_stand"), _obj("mouse", "mouse"),
          _obj("pad", "mouse_pad"), _obj("clock", "alarm_clock")),
         (press("clock", "the alarm clock's button is pressed to silence it"),
          put_on("phone", "stand", "the phone rests on the phone stand"),
          put_on("mouse", "pad", "the mouse lies on the mouse pad"))),
    Goal("prepare_breakfast",
         ("prepare breakfast", "make breakfast", "get breakfast ready", "fix me some breakfast"),
         (_obj("bread", "bread"), _obj("basket", "basket"), _obj("cup", "cup"),
          _obj("coaster", "coaster"), _obj("bell", "bell")),
         (put_in("bread", "basket", "the bread is in the basket"),
          put_on("cup", "coaster", "the cup stands on the coaster"),
          press("bell", "the bell is rung to call for breakfast"))),
    Goal("tidy_the_desk",
         ("tidy the desk", "clean up the desk", "organise my desk", "declutter the workspace"),
         (_obj("phone", "phone"), _obj("stand", "phone_stand"), _obj("mouse", "mouse"),
          _obj("pad", "mouse_pad"), _obj("seal", "seal"), _obj("mat", "stamp_mat")),
         (put_on("phone", "stand", "the phone rests on the phone stand"),
          put_on("mouse", "pad", "the mouse lies on the mouse pad"),
          put_on("seal", "mat", "the seal stands on its mat"))),
    Goal("set_the_table",
         ("set the table", "lay the table", "get the table ready for a meal", "prepare the table for dinner"),
         (_obj("cup", "cup"), _obj("coaster", "coaster"), _obj("bread", "bread"),
          _obj("basket", "basket"), _obj("bell", "bell")),
         (put_on("cup", "coaster", "the cup stands on the coaster"),
          put_in("bread", "basket", "the bread is in the basket"),
          press("bell", "the bell is rung to announce the meal"))),
    Goal("sort_blocks_by_colour",
         ("sort the blocks by colour", "sort blocks by color", "arrange the blocks red green blue",
          "order the blocks by colour from left to right"),
         (_obj("red", "block", "red"), _obj("green", "block", "green"), _obj("blue", "block", "blue")),
         (put_at("red", (ROW_X, 0.12), "the red block is at the left end of the row"),
          put_at("green", (ROW_X, 0.0), "the green block is right of the red block", left_of=None),
          put_at("blue", (ROW_X, -0.12), "the blue block is at the right end of the row"))),
    Goal("build_a_tower",
         ("build a tower", "stack the blocks into a tower", "make a tower of blocks",
          "pile the blocks up"),
         (_obj("base", "block", "red"), _obj("middle", "block", "green"), _obj("top", "block", "blue"),
          _obj("bell", "bell")),
         (put_on("middle", "base", "the green block is stacked on the red block"),
          put_on("top", "middle", "the blue block is stacked on the green block"),
          press("bell", "the bell is rung to show the tower is done"))),
    Goal("do_the_paperwork",
         ("do the paperwork", "finish the office work", "handle the paperwork",
          "stamp and staple the documents"),
         (_obj("seal", "seal"), _obj("mat", "stamp_mat"), _obj("stapler", "stapler"),
          _obj("mouse", "mouse"), _obj("pad", "mouse_pad")),
         (put_on("seal", "mat", "the seal is stamped onto the mat"),
          press("stapler", "the stapler is pressed down"),
          put_on("mouse", "pad", "the mouse lies on the mouse pad"))),
    Goal("shut_down_for_the_night",
         ("shut down for the night", "turn everything off", "switch things off before leaving",
          "close up the office"),
         (_obj("switch", "switch"), _obj("clock", "alarm_clock"), _obj("phone", "phone"),
          _obj("stand", "phone_stand")),
         (press("switch", "the switch is flipped", point="on"),
          press("clock", "the alarm clock's button is pressed"),
          put_on("phone", "stand", "the phone is put on its stand to charge"))),
    Goal("display_the_fruit",
         ("display the fruit", "show off the fruit", "put the fruit on display", "arrange the fruit nicely"),
         (_obj("apple", "apple"), _obj("stand", "object_stand"), _obj("orange", "orange"),
          _obj("plate", "plate"), _obj("bread", "bread"), _obj("basket", "basket")),
         (put_on("apple", "stand", "the apple sits on the display stand"),
          put_on("orange", "plate", "the orange lies on the plate"),
          put_in("bread", "basket", "the bread is in the basket"))),
    Goal("serve_tea",
         ("serve tea", "serve a drink", "bring the tea", "get a drink ready"),
         (_obj("cup", "cup"), _obj("coaster", "coaster"), _obj("bowl", "bowl"), _obj("plate", "plate"),
          _obj("bell", "bell")),
         (put_on("cup", "coaster", "the cup stands on the coaster"),
          put_on("bowl", "plate", "the bowl stands on the plate"),
          press("bell", "the bell is rung to call for tea"))),
    Goal("tidy_the_kitchen",
         ("tidy the kitchen", "clear away the dishes", "stack the dishes", "clean up the kitchen counter"),
         (PlanObject(name="small", type="bowl", scale=0.85), _obj("large", "bowl"), _obj("cup", "cup"),
          _obj("coaster", "coaster"), _obj("bread", "bread"), _obj("basket", "basket")),
         (put_in("small", "large", "the smaller bowl is nested inside the larger one"),
          put_on("cup", "coaster", "the cup stands on the coaster"),
          put_in("bread", "basket", "the bread is put away in the basket"))),
    # -- goals of 4 to 6 subtasks, and goals whose subtasks depend on each other ----------------------
    Goal("raise_a_skyscraper",
         ("raise a skyscraper", "put up a block skyscraper", "erect a skyscraper",
          "a skyscraper of blocks"),
         (_obj("first", "block", "red"), _obj("second", "block", "green"), _obj("third", "block", "blue"),
          _obj("fourth", "block", "yellow"), _obj("bell", "bell")),
         (put_on("second", "first", "the green block is stacked on the red block"),
          put_on("third", "second", "the blue block is stacked on the green block"),
          put_on("fourth", "third", "the yellow block tops the four-block skyscraper"),
          press("bell", "the bell is rung to show the skyscraper stands"))),
    Goal("nest_and_stow",
         ("nest and stow", "nest them and stow them on the plate", "stow the nested set away",
          "nest and stow the set"),
         (PlanObject(name="small", type="bowl", scale=0.85), PlanObject(name="large", type="bowl", scale=1.0),
          _obj("plate", "plate"), _obj("bell", "bell")),
         (put_in("small", "large", "the smaller bowl is nested in the larger one"),
          # depends on the first: the larger bowl is carried with the smaller one nested in it
          put_on("large", "plate", "the nested bowls are moved onto the plate together"),
          press("bell", "the bell is rung once the bowls are stowed"))),
    Goal("weigh_the_fruit",
         ("weigh the fruit", "weigh the apple and the orange", "put the fruit on the scale one by one",
          "check what the fruit weighs"),
         (_obj("apple", "apple"), _obj("orange", "orange"), _obj("scale", "kitchen_scale"),
          _obj("bowl", "bowl"), _obj("bell", "bell")),
         (put_on("apple", "scale", "the apple is weighed on the kitchen scale"),
          put_in("apple", "bowl", "the weighed apple is put into the bowl"),
          put_on("orange", "scale", "the orange is weighed on the now free scale"),
          press("bell", "the bell is rung when the weighing is done"))),
    Goal("morning_routine",
         ("do the morning routine", "start my morning routine", "wake up routine",
          "run through my morning routine"),
         (_obj("clock", "alarm_clock"), _obj("cup", "cup"), _obj("coaster", "coaster"),
          _obj("phone", "phone"), _obj("stand", "phone_stand"), _obj("bell", "bell")),
         (press("clock", "the alarm clock is silenced"),
          put_on("cup", "coaster", "the cup stands on the coaster"),
          put_on("phone", "stand", "the phone rests on its stand"),
          press("bell", "the bell is rung for breakfast"),
          press("clock", "the alarm is set again for tomorrow"))),
    Goal("finish_the_shift",
         ("finish the shift", "wrap up the shift", "end of shift routine", "close out the shift"),
         (_obj("seal", "seal"), _obj("mat", "stamp_mat"), _obj("stapler", "stapler"),
          _obj("mouse", "mouse"), _obj("pad", "mouse_pad"), _obj("phone", "phone"),
          _obj("stand", "phone_stand"), _obj("bell", "bell")),
         (put_on("seal", "mat", "the seal is stamped onto the mat"),
          press("stapler", "the stapler is pressed down"),
          put_on("mouse", "pad", "the mouse lies on the mouse pad"),
          put_on("phone", "stand", "the phone is put on its stand"),
          press("bell", "the bell is rung to end the shift"))),
    Goal("fast_food_order",
         ("fast food order", "serve a fast food order", "get the fast food ready",
          "a burger and fries to go"),
         (_obj("burger", "burger"), _obj("plate", "plate"), _obj("fries", "fries"),
          _obj("basket", "basket"), _obj("bell", "bell")),
         (put_on("burger", "plate", "the burger is on the plate"),
          put_in("fries", "basket", "the fries are in the basket"),
          press("bell", "the bell is rung: order up"))),
    Goal("sort_the_recycling",
         ("sort the recycling", "recycle the bottle and the can", "deal with the recycling",
          "throw away the empties"),
         (_obj("bottle", "bottle"), _obj("bin", "dustbin"), _obj("can", "can"),
          _obj("box", "plastic_box"), _obj("switch", "switch")),
         (put_in("bottle", "bin", "the bottle is in the dustbin"),
          put_in("can", "box", "the can is in the plastic box"),
          press("switch", "the switch is flipped", point="on"))),
    Goal("tidy_the_hallway",
         ("tidy the hallway", "put my shoe away in the hallway", "clear the entryway",
          "tidy the entrance hall"),
         (_obj("shoe", "shoe"), _obj("box", "shoe_box"), _obj("phone", "phone"),
          _obj("stand", "phone_stand"), _obj("switch", "switch")),
         (put_in("shoe", "box", "the shoe is in the shoe box"),
          put_on("phone", "stand", "the phone rests on its stand"),
          press("switch", "the hall light switch is flipped", point="on"))),
    Goal("medicine_time",
         ("time for my medicine", "time for my pills", "get my medication ready", "bring my pills and water"),
         (_obj("pills", "pill_bottle"), _obj("plate", "plate"), _obj("cup", "cup"),
          _obj("coaster", "coaster"), _obj("bell", "bell")),
         (put_on("pills", "plate", "the pill bottle is on the plate"),
          put_on("cup", "coaster", "the cup of water stands on the coaster"),
          press("bell", "the bell is rung: medicine is ready"))),
    Goal("cool_down_the_room",
         ("cool down the room", "set up the fan", "it is too hot in here", "turn on the fan"),
         (_obj("fan", "fan"), _obj("pad", "mouse_pad"), _obj("switch", "switch"), _obj("cup", "cup"),
          _obj("coaster", "coaster")),
         (put_on("fan", "pad", "the fan stands on the pad", also=(holds("upright", "fan"),)),
          press("switch", "the fan's switch is flipped on", point="on"),
          put_on("cup", "coaster", "a cold drink stands on the coaster"))),
    Goal("stow_the_soap",
         ("stow the soap", "tuck the soap away", "keep the soap out of sight", "store the soap"),
         (_obj("soap", "soap"), _obj("cabinet", "cabinet")),
         (open_drawer("cabinet", "the cabinet's drawer is pulled open"),
          # each depends on the one before: the soap goes into the open drawer, which is then shut (the
          # soap, hidden in it then, is not checked again: no view shows it)
          put_in("soap", "cabinet", "the soap lies in the open drawer"),
          close_drawer("cabinet", "the drawer is shut with the soap inside"))),
    Goal("clear_the_washstand",
         ("clear the washstand", "tidy the washstand", "clean up the sink area", "tidy up after washing"),
         (_obj("sponge", "sponge"), _obj("cabinet", "cabinet"), _obj("cup", "cup"),
          _obj("coaster", "coaster")),
         (put_on("cup", "coaster", "the cup stands on the coaster"),
          open_drawer("cabinet", "the cabinet's drawer is pulled open"),
          put_in("sponge", "cabinet", "the sponge lies in the open drawer"),
          close_drawer("cabinet", "the drawer is shut with the sponge inside"))),
    Goal("block_city",
         ("block city", "lay out a block city", "play block city", "set out a little block city"),
         (_obj("red", "block", "red"), _obj("green", "block", "green"), _obj("blue", "block", "blue"),
          _obj("orange", "block", "orange"), _obj("yellow", "block", "yellow"),
          _obj("purple", "block", "purple"), _obj("bell", "bell")),
         (press("bell", "the bell is rung to start building"),
          put_on("green", "red", "the green block is stacked on the red block"),
          put_on("blue", "green", "the blue block tops the first three-block building"),
          put_on("yellow", "orange", "the yellow block is stacked on the orange block"),
          put_on("purple", "yellow", "the purple block tops the second three-block building"),
          press("bell", "the bell is rung: the block city is finished"))),
    Goal("open_the_front_desk",
         ("open the front desk", "get the reception ready for visitors", "set up the front desk",
          "prepare the reception desk"),
         (_obj("board", "qr_board"), _obj("phone", "phone"), _obj("stand", "phone_stand"),
          _obj("bell", "bell")),
         (turn_to_face("board", "the QR code board is turned to face the robot, standing on the table"),
          put_on("phone", "stand", "the phone rests on the phone stand"),
          press("bell", "the bell is rung: the desk is open"))),
    Goal("tidy_the_coffee_corner",
         ("tidy the coffee corner", "clear up the coffee station", "put the coffee things away",
          "tidy up after coffee"),
         (_obj("mug", "mug"), _obj("rack", "mug_rack"), _obj("cup", "cup"), _obj("coaster", "coaster"),
          _obj("bell", "bell")),
         (hang("mug", "rack", "the mug hangs on the rack's peg by its handle"),
          put_on("cup", "coaster", "the cup stands on the coaster"),
          press("bell", "the bell is rung: the coffee corner is tidy"))),
)
