"""Put object A to the right of object B."""

from vcage.tasks.base import TASKS
from vcage.tasks.library.place_a2b_left import PlaceA2B


@TASKS.register("place_a2b_right")
class PlaceA2BRight(PlaceA2B):
    side = -1
