"""The gallery's order: from the first solve to a sweep, as a reader would take them."""

from __future__ import annotations

#: The examples in reading order; one not listed comes after them, by file name.
ORDER = (
    "plot_first_solve.py",
    "plot_creep_settlement.py",
    "plot_eccentric_liftoff.py",
    "plot_stepped_punch.py",
    "plot_design_code_creep.py",
    "plot_eccentricity_sweep.py",
)


class ReadingOrder:
    """A sort key of sphinx-gallery (``within_subsection_order``)."""

    def __init__(self, src_dir: str) -> None:
        self.src_dir = src_dir

    def __call__(self, filename: str) -> tuple[int, str]:
        return (ORDER.index(filename) if filename in ORDER else len(ORDER), filename)

    def __repr__(self) -> str:  # sphinx-gallery compares configurations by their repr
        return f"<{type(self).__name__} {ORDER}>"
