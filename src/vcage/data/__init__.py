"""Datasets in the LeRobot v3 layout: an atomic per-episode writer, a reader, and vcage extras."""

from vcage.data.lerobot import DatasetWriter
from vcage.data.reader import DatasetReader, Episode, Feature
from vcage.data.repair import repair
from vcage.data.repair_report import RepairReport
from vcage.data.verify import check, verify
from vcage.data.verify_report import Problem, VerifyReport

__all__ = ["DatasetReader", "DatasetWriter", "Episode", "Feature", "Problem", "RepairReport", "VerifyReport",
           "check", "repair", "verify"]
