"""core.engines.projection."""
