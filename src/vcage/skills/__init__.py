"""Skills: inverse kinematics, motion plans, their execution, and manipulation primitives."""
