"""Packages that only one feature needs, imported when that feature is used.

The solver itself needs numpy and scipy alone; studies on Dask, datasets, the
finite-element check, plots and the report each need more. A missing package raises
:class:`MissingDependency` naming the feature and the pip extra that installs it, not a
bare ``ModuleNotFoundError`` from deep inside the feature.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from types import ModuleType
from typing import Any

#: The pip extra of ``coated-punch`` that installs each optional module (the one source;
#: ``pyproject.toml`` declares the extras, and a test checks the two agree).
EXTRA_OF: dict[str, str] = {
    "dask": "studies",
    "distributed": "studies",
    "pyarrow": "parquet",
    "xarray": "data",
    "pandas": "data",
    "skfem": "fem",
    "holoviews": "plot",
    "bokeh": "plot",
    "matplotlib": "report",
}

#: The distribution that provides a module, where its name differs from the module's.
DISTRIBUTION_OF: dict[str, str] = {"skfem": "scikit-fem"}


__all__ = ["DISTRIBUTION_OF", "EXTRA_OF", "MissingDependency", "import_optional"]


class MissingDependency(ImportError):
    """An optional package a feature needs is not installed."""


def import_optional(module: str, feature: str) -> ModuleType:
    """Import ``module`` (a dotted name is fine) for ``feature``.

    Parameters
    ----------
    module : str
        The module to import, e.g. ``"xarray"`` or ``"distributed.diagnostics"``.
    feature : str
        What needs it, as the user would say it (``"a study's dataset"``).

    Raises
    ------
    MissingDependency
        If the module's top-level package is not installed; the message names the
        feature, the package and the ``pip install`` that brings it.
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as error:
        top = module.split(".")[0]
        if error.name is not None and error.name.split(".")[0] != top:
            raise  # the package is there but one of its own dependencies is broken
        extra = EXTRA_OF.get(top, "all")
        package = DISTRIBUTION_OF.get(top, top)
        raise MissingDependency(
            f"{package} is needed for {feature} and is not installed: "
            f"pip install 'coated-punch[{extra}]'") from error


def lazy_exports(package: str, exports: Mapping[str, str], namespace: dict[str, Any]
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__`` (PEP 562) for names loaded on first use.

    ``exports`` maps each such name to the module that defines it; ``namespace`` is the
    package's ``globals()``, where a name loaded once is kept (later lookups skip
    ``__getattr__``). Used where importing a module up front would slow every start (the
    command line) for a feature few calls need.
    """
    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(namespace.get("__all__", ())))

    return __getattr__, __dir__
