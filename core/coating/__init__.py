"""core.coating."""
