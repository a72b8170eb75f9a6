"""Atomic tasks: scene, scripted expert and success evaluation, one file per task."""

from vcage.tasks.base import TASKS, AtomicTask, Item
from vcage.tasks.runner import EpisodeResult, run_episode

__all__ = ["TASKS", "AtomicTask", "EpisodeResult", "Item", "run_episode"]
