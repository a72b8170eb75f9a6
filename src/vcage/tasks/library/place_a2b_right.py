"""Put object A to the right of object B."""

from vcage.scene.layout import Relation
from vcage.tasks.base import TASKS
from vcage.tasks.library.place_a2b_left import PlaceA2B, target_zone


@TASKS.register("place_a2b_right")
class PlaceA2BRight(PlaceA2B):
    side = -1
    relations = (Relation("left_of", "a", "b", 0.1),)  # A starts on the other side
    reserved = (target_zone(-1),)
