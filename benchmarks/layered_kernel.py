"""The exact layered kernel against the resolved FE model, flat punch, uniform coating.

    python -m benchmarks.layered_kernel            # the table below, written to
                                                    # benchmarks/results/layered_kernel.md

For ``sum h / 2a = 0.02, 0.05``, ``E_c / E = 0.05, 1, 3``, ``nu_c = 0.3, 0.45``, smooth and
bonded, ``H = a``, base ``nu = 0.2``: the force per unit settlement and the moment per unit
tilt of :func:`core.engines.layered.flat_punch_stiffness` (the layered kernel) and of the
thin-layer model (:func:`benchmarks.coating_validity.fast_stiffness` with the compliance of
:func:`core.coating.layer_compliance`), each as a relative difference from the FE
model of :mod:`core.coating.fem_check` at mesh level 1; the FE model's own discretisation error is
shown as the difference of its levels 0 and 1.
"""

from __future__ import annotations

import itertools
import time
from pathlib import Path

import numpy as np

from benchmarks.coating_validity import BASE_POISSON, fast_stiffness
from core.coating import CoatingStrip, Stack, layer_compliance, solve_stack
from core.engines.layered.stiffness import flat_punch_stiffness
from core.kernel import UniformLayer

THICKNESS_RATIOS = (0.02, 0.05)
MODULUS_RATIOS = (0.05, 1.0, 3.0)
COATING_POISSON = (0.3, 0.45)
INTERFACES = ("smooth", "bonded")
ROOT = Path(__file__).resolve().parent.parent
THIN_LAYER_NOTE = (
    "The thin-layer columns are the fast model's unit stiffnesses in full contact (the FE "
    "model ties the punch to the surface), as in `benchmarks/coating_validity.py`.\n")


def _strip(h: float, modulus: float, poisson: float, interface: str) -> CoatingStrip:
    return CoatingStrip(lambda x: np.full(np.shape(x), h),
                        lambda x: np.full(np.shape(x), modulus),
                        lambda x: np.full(np.shape(x), poisson), interface)


def compare(ratio: float, modulus: float, poisson: float, interface: str) -> dict:
    """Relative differences from FE level 1 (force, moment) of the layered kernel, the
    thin-layer model and FE level 0; and the seconds of the layered solve."""
    h = 2.0 * ratio
    stack = Stack(1.0, (_strip(h, modulus, poisson, interface),), 1.0, 1.0, BASE_POISSON)
    fine = solve_stack(stack, level=1)
    coarse = solve_stack(stack, level=0)
    start = time.perf_counter()
    layered = flat_punch_stiffness(1.0, [UniformLayer(h, modulus, poisson, interface)], 1.0,
                                   1.0, BASE_POISSON)
    seconds = time.perf_counter() - start
    thin = fast_stiffness(1.0, float(layer_compliance(h, modulus, poisson, interface)))
    ref = (fine.force_parts[1], fine.moment_parts[2])

    def rel(pair):
        return pair[0] / ref[0] - 1.0, pair[1] / ref[1] - 1.0

    return {"layered": rel((layered.force_per_settlement, layered.moment_per_tilt)),
            "thin": rel(thin), "fe0": rel((coarse.force_parts[1], coarse.moment_parts[2])),
            "seconds": seconds, "modes": layered.modes}


def main() -> None:
    lines = ["| sum h/2a | E_c/E | nu_c | interface | layered kernel P / M | "
             "thin layer P / M | FE level 0 P / M | modes | layered s |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for ratio, modulus, poisson, interface in itertools.product(
            THICKNESS_RATIOS, MODULUS_RATIOS, COATING_POISSON, INTERFACES):
        r = compare(ratio, modulus, poisson, interface)
        cells = [f"{100 * r[k][0]:+.4f} / {100 * r[k][1]:+.4f}" for k in ("layered", "fe0")]
        thin = f"{100 * r['thin'][0]:+.1f} / {100 * r['thin'][1]:+.1f}"
        line = (f"| {ratio} | {modulus} | {poisson} | {interface} | {cells[0]} | {thin} | "
                f"{cells[1]} | {r['modes']} | {r['seconds']:.2f} |")
        print(line, flush=True)
        lines.append(line)
    text = ("# Layered kernel against the resolved FE model\n\n"
            "Flat punch, uniform coating, H = a, base nu = 0.2; relative difference in % "
            "from FE level 1 of the force per unit settlement / moment per unit tilt. "
            "Made by `python -m benchmarks.layered_kernel` (timings on a shared, loaded "
            "2-core machine).\n\n" + "\n".join(lines) + "\n\n" + THIN_LAYER_NOTE)
    out = ROOT / "benchmarks" / "results" / "layered_kernel.md"
    out.write_text(text)
    print(f"written {out}")


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    main()
