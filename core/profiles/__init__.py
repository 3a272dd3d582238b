"""core.profiles.build."""
