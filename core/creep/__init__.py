"""core.creep.models."""
