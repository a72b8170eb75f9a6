"""vcage: verified long-horizon robot manipulation datasets in simulation."""

from vcage.sim.gl import choose_gl_backend

# MUJOCO_GL must be set before mujoco is first imported; every vcage module imports this package
# first, so choosing the backend here covers them all.
choose_gl_backend()

__version__ = "0.1.0"
