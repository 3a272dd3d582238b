"""core.engines.nystrom."""
