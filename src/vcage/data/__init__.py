"""Datasets in the LeRobot v3 layout: an atomic per-episode writer, a reader, and vcage extras."""

from vcage.data.lerobot import DatasetWriter
from vcage.data.reader import DatasetReader, Episode, Feature

__all__ = ["DatasetReader", "DatasetWriter", "Episode", "Feature"]
