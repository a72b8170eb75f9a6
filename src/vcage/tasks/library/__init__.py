"""The built-in atomic tasks, one module each; importing registers them in ``TASKS``."""

from vcage.tasks.library import (  # noqa: F401
    blocks_ranking_rgb,
    click_alarmclock,
    click_bell,
    lift_pot,
    move_can_pot,
    place_a2b_left,
    place_a2b_right,
    place_bread_basket,
    place_empty_cup,
    place_mouse_pad,
    place_object_stand,
    place_phone_stand,
    press_stapler,
    stack_blocks_three,
    stack_blocks_two,
    stack_bowls_two,
    stamp_seal,
    turn_switch,
)
