"""core.study.definition."""
