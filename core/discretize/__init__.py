"""core.discretize."""
