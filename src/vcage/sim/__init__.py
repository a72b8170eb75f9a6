"""Simulation: the robot model, the world (stepping, state), and rendering."""
