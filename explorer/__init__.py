"""A live browser explorer of the coated-punch contact problem (Panel).

``create_app()`` builds one session; ``python -m explorer`` serves it. The state classes
in :mod:`explorer.model.state` turn widget values into the scene dicts of ``core`` and can be
used without a server.
"""

from __future__ import annotations

from typing import Any

__all__ = ["create_app", "ExplorerApp", "ExplorerState", "SolveController"]


def __getattr__(name: str) -> Any:
    # Panel is imported only when the page itself is wanted, not for the state classes.
    if name in ("create_app", "ExplorerApp"):
        from . import app

        return getattr(app, name)
    if name == "ExplorerState":
        from .model import ExplorerState

        return ExplorerState
    if name == "SolveController":
        from .solving import SolveController

        return SolveController
    raise AttributeError(f"module 'explorer' has no attribute {name!r}")
