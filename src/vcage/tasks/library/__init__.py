"""The built-in atomic tasks, one module each; importing registers them in ``TASKS``."""

from vcage.tasks.library import (  # noqa: F401
    blocks_ranking_rgb,
    stack_blocks_three,
    stack_blocks_two,
)
