"""Atomic tasks: scene layout, scripted expert and success in the predicate vocabulary.

Importing the package registers the built-in tasks (:mod:`vcage.tasks.library`) in ``TASKS``.
"""

from vcage.tasks import library  # noqa: F401  (registers the built-in tasks)
from vcage.tasks.base import TASKS, AtomicTask, Item, pred
from vcage.tasks.runner import EpisodeResult, make_task, place_scene, prepare, run_episode

__all__ = ["TASKS", "AtomicTask", "EpisodeResult", "Item", "make_task", "place_scene", "pred",
           "prepare", "run_episode"]
