"""core.engines.layered."""
