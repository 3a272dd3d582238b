"""A live browser explorer of the coated-punch contact problem (Panel).

``create_app()`` builds one session; ``python -m explorer`` serves it. ``README.md`` here
maps the subpackages: ``model`` (the state and the result on screen, without Panel),
``solving``, ``plots``, ``files``, ``views``, ``fixes``.
"""

from __future__ import annotations

from typing import Any

__all__ = ["ExplorerApp", "create_app"]


def __getattr__(name: str) -> Any:
    # Panel is imported only when the page itself is wanted: the solver workers and the
    # study processes import explorer.model and explorer.solving, and nothing else.
    if name in ("create_app", "ExplorerApp"):
        from . import app

        return getattr(app, name)
    raise AttributeError(f"module 'explorer' has no attribute {name!r}")
