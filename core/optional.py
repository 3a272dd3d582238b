"""Packages that only one feature needs, imported when that feature is used.

The solver itself needs numpy and scipy alone; studies on Dask, datasets, the
finite-element check, plots and the report each need more. A missing package raises
:class:`MissingDependency` naming the feature and the pip extra that installs it, not a
bare ``ModuleNotFoundError`` from deep inside the feature.
"""

from __future__ import annotations

import importlib
from types import ModuleType

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
            f"{feature} needs {package}, which is not installed: "
            f"pip install 'coated-punch[{extra}]'") from error
