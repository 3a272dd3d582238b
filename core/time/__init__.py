"""core.time."""
