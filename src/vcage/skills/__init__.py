"""Skills: IK, motion plans and their playback, and the manipulation primitives.

Importing the package registers the primitives in ``SKILLS``.
"""

from vcage.skills import drawers, hanging, primitives  # noqa: F401  (registers the primitives)
from vcage.skills.base import SKILLS, Skills

__all__ = ["SKILLS", "Skills"]
