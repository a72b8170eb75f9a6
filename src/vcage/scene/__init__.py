"""Scene specification and composition into a MuJoCo model."""
