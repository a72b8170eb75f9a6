"""Datasets in the LeRobot v3 layout: an atomic per-episode writer, a reader, and vcage extras."""

from vcage.data.lerobot import DatasetWriter
from vcage.data.reader import DatasetReader, Episode, Feature
from vcage.data.repair import RepairReport, repair
from vcage.data.verify import Problem, VerifyReport, check, verify

__all__ = ["DatasetReader", "DatasetWriter", "Episode", "Feature", "Problem", "RepairReport", "VerifyReport",
           "check", "repair", "verify"]
