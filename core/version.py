"""The package's version: the one source of truth (``pyproject.toml`` reads it from here,
``core.__version__`` re-exports it), recorded in every file the tool writes."""

#: A development version between releases (0.2.0 was released on 2026-11-29): what the
#: tool writes from a checkout is told apart from the release's.
VERSION = "0.3.0.dev0"
