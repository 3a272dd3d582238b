"""core.engines.collocation."""
