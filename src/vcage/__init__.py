"""vcage: verified long-horizon robot manipulation datasets in simulation."""

__version__ = "0.1.0"
