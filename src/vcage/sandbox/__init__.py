"""The sandbox for generated subtask code: a static allow-list, then a child process under limits.

Knows nothing of MuJoCo or of vcage's stages: a program is text, the skill API is a list of
signatures, the scene a snapshot of poses, and the result the list of skill calls the program
recorded, as JSON. The caller validates those calls and executes them (:mod:`vcage.subtasks`).
``child.py`` is the package's only module that compiles and executes text as code.
"""

from vcage.sandbox.policy import check
from vcage.sandbox.protocol import STATUSES, Call, RunResult, SceneSnapshot, SkillSignature
from vcage.sandbox.runner import Limits, run_program

__all__ = ["STATUSES", "Call", "Limits", "RunResult", "SceneSnapshot", "SkillSignature", "check",
           "run_program"]
