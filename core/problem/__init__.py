"""core.problem."""
