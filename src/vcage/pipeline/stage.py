"""Where an attempt ended: the stage that rejected it, or ``accepted``."""

from __future__ import annotations

from enum import StrEnum


class Stage(StrEnum):
    PLACEMENT = "placement"  # the layout could not be placed (no room for the objects asked for)
    SCENE = "scene"  # the placed scene failed the physics check (interpenetration, motion, fall)
    SKILL = "skill"  # a skill could not plan (unreachable, no grasp)
    PHYSICS = "physics"  # the simulation became unstable
    CRITIC = "critic"  # the critic rejected a subtask
    ACCEPTED = "accepted"
