"""core.kernel.plane."""
