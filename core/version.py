"""The package's version: the one source of truth (``pyproject.toml`` reads it from here,
``core.__version__`` re-exports it), recorded in every file the tool writes."""

VERSION = "0.2.0"
