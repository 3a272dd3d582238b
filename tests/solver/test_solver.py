"""The projection solver against analytic limits, manufactured solutions and itself.

Every tolerance below is a measured error with a margin; the measured value is quoted.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from core.discretize import base_panels, graded_cuts, kernel_operator, operator_rows
from core.problem import UnresolvedOperator
from core.solver import solve_dimensionless
from tests.support.points import whole_interval


def smooth_m(x):
    return 0.05 * (1.0 + 0.4 * x + 0.3 * x**2)


def jump_m(x):
    return np.where(x < 0.3, 0.05, 0.02)


# ------------------------------------------------------------------ analytic limits


def test_winkler_limit_thin_base():
    """lam large: F q -> q/(2 lam), so q = P/2 and delta = P/2 (m + 1/(2 lam)).

    The edge zones (width ~1/lam) carry a different pressure, which shifts the interior by
    O(1/(m lam^2)): measured 1.79e-4 at lam = 50 and 4.63e-5 at lam = 100 (ratio 3.87).
    """
    m, p = 0.1, 1.0
    deviation = {}
    for lam in (50.0, 100.0):
        sol = solve_dimensionless(lam, m, 0.0, [1.0], force=p, moment=0.0, tol=1e-10)
        q = sol.pressure(np.linspace(-0.5, 0.5, 11))[:, 0]
        delta_local = p / 2 * (m + 1 / (2 * lam))
        deviation[lam] = np.max(np.abs(q - p / 2)) / (p / 2)
        assert abs(sol.settlement[0] - delta_local) / delta_local < 2.5e-4
        assert abs(sol.tilt[0]) < 1e-15
    assert deviation[50.0] < 2.5e-4
    assert deviation[100.0] < deviation[50.0] / 3.5  # the limit is approached as 1/lam^2


def test_thick_base_tiny_m_gives_square_root_pressure():
    """lam small, m -> 0: the rigid punch on a half-space, q = P/(pi sqrt(1 - x^2)).

    The difference is the lam^2 term of the kernel (0.521 lam^2) plus O(m ln m): measured
    1.65e-3 at lam = 0.05 and 7.1e-4 at lam = 0.025 (|x| <= 0.8).
    """
    x = np.linspace(-0.8, 0.8, 17)
    exact = 1.0 / (np.pi * np.sqrt(1 - x**2))
    errors = []
    for lam in (0.05, 0.025):
        sol = solve_dimensionless(lam, 1e-4, 0.0, [1.0], force=1.0, moment=0.0, tol=1e-6)
        assert sol.success
        q = sol.pressure(x)[:, 0]
        errors.append(np.max(np.abs(q - exact) / exact))
    assert errors[0] < 2.5e-3
    assert errors[1] < errors[0] / 2


# ---------------------------------------------------------------- manufactured


def _exact_q(x):
    return 1.0 + 0.3 * x + 0.2 * np.cos(3 * x)


def _manufactured_gap(lam, m_fn, c=1.0, delta=0.02, alpha=0.004):
    """g = delta + alpha x - c m q - F q for the known q of _exact_q."""
    fine = base_panels(lam, (), max_width=0.05, edge_width=1e-6)
    q_nodes = _exact_q(fine.nodes)

    def g(x):
        x = np.atleast_1d(np.asarray(x, dtype=float))
        fq = operator_rows(lam, fine, x) @ q_nodes
        return delta + alpha * x - c * m_fn(x) * _exact_q(x) - fq

    return g


@pytest.mark.parametrize("statement", [1, 2, 3, 4])
def test_manufactured_solution_all_statements(statement):
    lam, delta, alpha = 1.0, 0.02, 0.004
    g = _manufactured_gap(lam, smooth_m, delta=delta, alpha=alpha)
    p = 2.0  # int q = 2 + 0.4 sin 3 /3 ... computed below exactly
    p = 2.0 + 0.2 * 2 * np.sin(3.0) / 3
    mom = 0.3 * 2 / 3  # int x q: only the odd part 0.3 x contributes
    given = {1: dict(settlement=delta, tilt=alpha), 2: dict(settlement=delta, moment=mom),
             3: dict(tilt=alpha, force=p), 4: dict(force=p, moment=mom)}[statement]
    sol = solve_dimensionless(lam, smooth_m, g, [1.0], tol=1e-9, **given)
    x = np.linspace(-0.95, 0.95, 39)
    err_q = np.max(np.abs(sol.pressure(x)[:, 0] - _exact_q(x))) / np.max(_exact_q(x))
    # measured: 1e-11 .. 4e-11 for the four statements at tol 1e-9
    assert err_q < 1e-9
    assert sol.settlement[0] == pytest.approx(delta, rel=1e-9)
    assert sol.tilt[0] == pytest.approx(alpha, rel=1e-8)
    assert sol.force[0] == pytest.approx(p, rel=1e-9)
    assert sol.moment[0] == pytest.approx(mom, rel=1e-9)
    assert sol.info["error_estimate"] <= 1e-9


# ------------------------------------------------------------------ structure


def test_even_data_gives_zero_tilt():
    sol = solve_dimensionless(1.0, lambda x: 0.05 * (1 + x**2), lambda x: 0.1 * x**2,
                              [1.0], force=1.0, moment=0.0, tol=1e-10)
    assert abs(sol.tilt[0]) < 1e-13 * abs(sol.settlement[0])  # measured 3e-17
    x = np.linspace(-1, 1, 21)
    q = sol.pressure(x)[:, 0]
    assert np.max(np.abs(q - q[::-1])) < 1e-12 * np.max(np.abs(q))


def test_equilibrium_holds():
    sol = solve_dimensionless(0.7, jump_m, lambda x: 0.05 * x**2, [1.0], force=1.3,
                              moment=0.2, breakpoints=[0.3], tol=1e-9, method="projection")
    # A rule exact for the piecewise polynomials of the basis: break at its element ends.
    cuts = graded_cuts((0.3,), 0.7, jump_m)
    panels = base_panels(0.7, tuple(sorted(set(cuts) | {0.3})), max_width=0.05)
    q = sol.pressure(panels.nodes)[:, 0]
    assert float(panels.integrate(q)) == pytest.approx(1.3, rel=1e-12)
    assert float(panels.integrate(panels.nodes * q)) == pytest.approx(0.2, rel=1e-11)


def test_four_statements_are_consistent():
    common = dict(breakpoints=[0.3], tol=1e-10)
    m, g = jump_m, (lambda x: 0.03 * np.where(x > -0.2, 1.0, 0.0) + 0.02 * x**2)
    common["breakpoints"] = [-0.2, 0.3]
    s4 = solve_dimensionless(0.8, m, g, [1.0], force=1.0, moment=0.1, **common)
    d, a = s4.settlement[0], s4.tilt[0]
    s1 = solve_dimensionless(0.8, m, g, [1.0], settlement=d, tilt=a, **common)
    s2 = solve_dimensionless(0.8, m, g, [1.0], settlement=d, moment=0.1, **common)
    s3 = solve_dimensionless(0.8, m, g, [1.0], tilt=a, force=1.0, **common)
    # measured: agreement to 3e-13 relative
    assert s1.force[0] == pytest.approx(1.0, rel=1e-10)
    assert s1.moment[0] == pytest.approx(0.1, rel=1e-9)
    assert s2.tilt[0] == pytest.approx(a, rel=1e-9)
    assert s2.force[0] == pytest.approx(1.0, rel=1e-10)
    assert s3.settlement[0] == pytest.approx(d, rel=1e-10)
    assert s3.moment[0] == pytest.approx(0.1, rel=1e-9)


# ------------------------------------------------------------------ convergence


#: The whole of [-1, 1] (the solver promises q there): 201 even points and 20 toward each
#: end, down to 1e-10 away.
X_WHOLE = whole_interval(201)


def test_graded_basis_convergence_on_smooth_coating():
    """Settlement and q on the whole of [-1, 1] against n = 512 for a smooth coating.

    Measured (n = 32, 64, 128, 256): settlement 4.7e-7, 1.4e-9, 8.7e-14, 0; q 7.4e-3,
    8.9e-4, 1.3e-5, 6.9e-8: faster than any power, as hp grading promises (the reference
    is within 1e-9 of the Nystrom engine at tol 1e-11).
    """
    x = X_WHOLE
    ref = solve_dimensionless(1.0, smooth_m, 0.0, [1.0], force=1.0, moment=0.2, n_modes=512)
    q_ref = ref.pressure(x)[:, 0]
    err_s, err_q = [], []
    for n in (32, 64, 128, 256):
        s = solve_dimensionless(1.0, smooth_m, 0.0, [1.0], force=1.0, moment=0.2, n_modes=n)
        err_s.append(abs(s.settlement[0] - ref.settlement[0]) / ref.settlement[0])
        err_q.append(np.max(np.abs(s.pressure(x)[:, 0] - q_ref)) / np.max(np.abs(q_ref)))
    for k in range(3):
        assert err_s[k + 1] < err_s[k] / 16  # at least order 4 per doubling; measured 300+
        assert err_q[k + 1] < err_q[k] / 5  # measured 8.3, 67, 190
    assert err_q[-1] < 3e-7


def test_modulus_jump_graded_basis_beats_the_seeds():
    """A jump of m: at n = 128 the error of q on the whole of [-1, 1] (both sides of the
    jump) is 5.2e-3 (global, the seed's basis), 5.7e-3 (piecewise) and 4.6e-4 (graded),
    against n = 512 graded (within 5e-8 of the Nystrom engine at tol 1e-11)."""
    kw = dict(force=1.0, moment=0.2, breakpoints=[0.3])
    ref = solve_dimensionless(1.0, jump_m, 0.0, [1.0], n_modes=512, **kw)
    x = whole_interval(201, jumps=(0.3,))
    x = x[x != 0.3]
    q_ref = ref.pressure(x)[:, 0]
    err = {}
    for kind in ("global", "piecewise", "graded"):
        s = solve_dimensionless(1.0, jump_m, 0.0, [1.0], n_modes=128, basis=kind, **kw)
        err[kind] = np.max(np.abs(s.pressure(x)[:, 0] - q_ref)) / np.max(np.abs(q_ref))
    assert err["graded"] < err["global"] / 5
    assert err["graded"] < err["piecewise"] / 5


# ------------------------------------------------------------------ creep


def _ode_oracle(lam, m, amp, rate, p, mom, times, max_width=0.1):
    """Nodal (Nystrom) oracle for K = -amp exp(-rate (t - tau)), c = 1, g = 0.

    With Y = V[F q], Y' = -rate Y - amp F q, and the static system
    m q + F q = delta + alpha x + Y, int q = P, int x q = M, Y is a linear ODE
    Y' = B Y + f solved exactly with a matrix exponential.
    """
    panels = base_panels(lam, (), max_width=max_width)
    f_mat = kernel_operator(lam, panels).matrix
    n = panels.size
    x, w = panels.nodes, panels.weights
    sys = np.zeros((n + 2, n + 2))
    sys[:n, :n] = m * np.eye(n) + f_mat
    sys[:n, n] = -1.0
    sys[:n, n + 1] = -x
    sys[n, :n] = w
    sys[n + 1, :n] = w * x
    inv = np.linalg.inv(sys)
    # q = Qy Y + q0 with the load part q0
    q_of_y = inv[:n, :n]
    q0 = inv[:n, n:] @ np.array([p, mom])
    b = -rate * np.eye(n) - amp * f_mat @ q_of_y
    f = -amp * f_mat @ q0
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n] = b
    aug[:n, n] = f
    out = []
    for t in times:
        y = expm(aug * (t - 1.0))[:n, n]
        sol = inv @ np.concatenate([y, [p, mom]])
        out.append((sol[n], sol[n + 1]))
    return np.array(out)


def test_creep_against_ode_oracle():
    from core.creep.models import ExponentialCreep

    model = ExponentialCreep(modulus=3e10, compliance=6e-11, rate=0.05)
    kernel = model.dimensionless_kernel(28.0)
    amp = -float(kernel.exponential_parts(np.array([1.0]))[0, 0])
    rate = float(kernel.rates[0])
    times = np.array([1.0, 1.5, 3.0, 10.0, 30.0])
    sol = solve_dimensionless(1.0, 0.05, 0.0, times, kernel=kernel, force=1.0, moment=0.1,
                              tol=1e-9)
    ref = _ode_oracle(1.0, 0.05, amp, rate, 1.0, 0.1, times)
    # measured: 2e-12 (settlement), 5e-12 (tilt) relative
    assert np.max(np.abs(sol.settlement - ref[:, 0]) / ref[:, 0]) < 1e-9
    assert np.max(np.abs(sol.tilt - ref[:, 1]) / np.abs(ref[:, 1])) < 1e-9
    # creep: the settlement grows over time under a constant force
    assert np.all(np.diff(sol.settlement) > 0)


def test_general_kernel_path_matches_degenerate():
    from core.creep.models import ExponentialCreep

    kernel = ExponentialCreep(modulus=3e10, compliance=6e-11, rate=0.05).dimensionless_kernel(28)
    times = np.array([1.0, 2.0, 5.0])
    a = solve_dimensionless(1.0, 0.05, 0.0, times, kernel=kernel, force=1.0, moment=0.1,
                            tol=1e-8)
    b = solve_dimensionless(1.0, 0.05, 0.0, times, kernel=lambda t, s: kernel(t, s),
                            force=1.0, moment=0.1, tol=1e-6)
    assert np.max(np.abs(a.settlement - b.settlement) / a.settlement) < 1e-6


# ------------------------------------------------------------------ caching


def test_load_change_recomputes_no_spatial_stage(stage_evaluations):
    kw = dict(breakpoints=[0.3], tol=1e-8, method="projection")
    solve_dimensionless(1.3, jump_m, lambda x: 0.01 * x**2, [1.0, 2.0], force=1.0,
                        moment=0.0, **kw)
    before = stage_evaluations()
    sol = solve_dimensionless(1.3, jump_m, lambda x: 0.01 * x**2, [1.0, 2.0], force=2.5,
                              moment=0.3, **kw)
    after = stage_evaluations()
    for stage in ("panels", "operator", "basis", "galerkin", "gap", "modes"):
        assert before[stage] >= 1, stage  # the first solve built it
        assert after[stage] == before[stage], stage
    assert all(v["cached"] for k, v in sol.info["stages"].items()
               if k in ("panels", "operator", "basis", "galerkin", "gap", "modes"))


def test_gap_change_reuses_operator_and_basis(stage_evaluations):
    # Below DIRECT_LARGEST_BELOW one basis is built (not one per cap tried).
    kw = dict(tol=1e-8, method="projection")
    solve_dimensionless(1.1, smooth_m, lambda x: 0.01 * x**2, [1.0], force=1.0, moment=0.0,
                        **kw)
    before = stage_evaluations()
    solve_dimensionless(1.1, smooth_m, lambda x: 0.02 * x**2, [1.0], force=1.0, moment=0.0,
                        **kw)
    after = stage_evaluations()
    assert after["operator"] == before["operator"]
    assert after["basis"] == before["basis"]
    assert after["galerkin"] == before["galerkin"]
    assert after["gap"] == before["gap"] + 1


def test_a_coating_scaled_as_a_whole_reuses_the_basis(stage_evaluations):
    """The basis for m = s m1 is sqrt(s) times the basis for m1: a thickness or modulus
    slider of a uniform coating builds no new basis, and the answers stay right. (Only
    while the graded mesh keeps its layers: 0.05 and 0.052 both get 19 geometric layers
    toward each end.)"""
    times = [1.0]
    first = solve_dimensionless(1.0, 0.05, 0.0, times, force=1.0, moment=0.1, tol=1e-8,
                                method="projection")
    before = stage_evaluations()
    second = solve_dimensionless(1.0, 0.052, 0.0, times, force=1.0, moment=0.1, tol=1e-8,
                                 method="projection")
    after = stage_evaluations()
    assert after["basis"] == before["basis"]
    assert after["galerkin"] == before["galerkin"] + 1
    # a softer coating settles more; both answers claim tol
    assert second.settlement[0] > first.settlement[0]
    assert first.info["success"] and second.info["success"]


# ------------------------------------------------------------------ flags & errors


def test_contact_lost_flag_for_large_eccentricity():
    # the flag belongs to the full-contact model ("auto" would answer with lift-off)
    sol = solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.6, tol=1e-8,
                              contact="full")
    assert "contact_lost" in sol.info["flags"]
    ok = solve_dimensionless(1.0, 0.05, 0.0, [1.0], force=1.0, moment=0.05, tol=1e-8,
                             contact="full")
    assert "contact_lost" not in ok.info["flags"]


@pytest.mark.parametrize("kwargs, field", [
    (dict(lam=-1.0), "lam"),
    (dict(lam=float("nan")), "lam"),
    (dict(m=-0.1), "m"),
    (dict(m=lambda x: 0.1 - x), "m"),
    (dict(g=float("inf")), "g"),
    (dict(times=[0.5]), "times"),
    (dict(times=[2.0, 1.5]), "times"),
    (dict(c=0.0), "c"),
    (dict(force=None), "given"),
    (dict(settlement=0.1), "given"),
    (dict(breakpoints=[1.5]), "breakpoints"),
    (dict(tol=0.0), "tol"),
    (dict(force=float("nan")), "force"),
    # beyond double precision in the Galerkin matrix: once LinAlgError or NaN
    (dict(m=1e200), "m"),
    (dict(m=1e-300), "m"),
    (dict(g=lambda x: 1e150 * x**2), "g"),
    (dict(force=1e120), "force"),
    (dict(lam=1e4), "lam"),  # a 550 GB operator
])
def test_bad_input_names_the_argument(kwargs, field):
    args = dict(lam=1.0, m=0.1, g=0.0, times=[1.0], force=1.0, moment=0.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=rf"^{field}"):
        solve_dimensionless(args.pop("lam"), args.pop("m"), args.pop("g"), args.pop("times"),
                            **args)


def test_times_as_text_are_refused_not_read_as_numbers() -> None:
    """``solve_dimensionless(..., "1.0", ...)`` was answered at t = 1: NumPy reads the
    string as a number. Text is refused naming ``times``; numbers in a list still go."""
    import pytest

    from core import solve_dimensionless

    for times in ("1.0", ["1.0", "2.0"], b"1"):
        with pytest.raises(ValueError, match=r"^times: must be an array of numbers, got text"):
            solve_dimensionless(1.0, 0.05, 0.0, times, force=1.0, moment=0.0)
    assert solve_dimensionless(1.0, 0.05, 0.0, [1.0, 2.0], force=1.0,
                               moment=0.0).times.tolist() == [1.0, 2.0]


def test_a_creeping_span_too_short_to_step_is_refused_naming_times() -> None:
    """Output times 1e-9 after loading on a creeping base raised numpy's LinAlgError
    ("Singular matrix", in the dense output's weights: the first steps fell below the
    doubles' spacing at t ~ 1). They are refused naming ``times``; a span of 5e-7, close
    outputs inside a longer span, and an elastic base are answered."""
    import pytest

    from core import solve_dimensionless
    from core.limits import MIN_CREEP_SPAN

    def kernel(t, tau):
        return -2.4 * np.exp(-2.9 * (t - tau))

    kw = dict(kernel=kernel, force=1.0, moment=0.1, tol=1e-6, contact="full")
    for method in (None, "projection"):
        with pytest.raises(ValueError, match=r"^times: on a creeping base the last output"):
            solve_dimensionless(1.0, 0.05, 0.0, [1.0, 1.0 + 1e-9], method=method, **kw)
        for times in ([1.0, 1.0 + MIN_CREEP_SPAN], [1.0, 1.0 + 1e-9, 2.0]):
            sol = solve_dimensionless(1.0, 0.05, 0.0, times, method=method, **kw)
            assert sol.info["success"] and np.all(np.isfinite(sol.settlement))
    elastic = solve_dimensionless(1.0, 0.05, 0.0, [1.0, 1.0 + 1e-12], force=1.0, moment=0.1)
    assert elastic.info["success"]


# (the ~1e50 times softer base: the grid's responses overflow and its factor is singular
# on the way to the engine declining it)
@pytest.mark.filterwarnings("ignore::RuntimeWarning", "ignore::scipy.linalg.LinAlgWarning")
def test_a_kernel_that_takes_the_compliance_through_zero_is_refused_naming_it() -> None:
    """A kernel of 1e99 (a fuzzer's) failed deep in the default engine with "cannot
    convert float NaN to integer"; one of -1e50 (a base 1e50 times softer after creep)
    too. The first describes no material: 1 - int_1^t K du is the held stress's
    compliance over the elastic one, and it goes negative. The second is a material the
    engine cannot resolve: it declines, as for any grid it cannot resolve."""
    def constant(value: float):
        return lambda t, tau: np.full(np.broadcast(t, tau).shape, value)

    for method in (None, "projection", "collocation"):
        with pytest.raises(ValueError, match=r"^kernel: the compliance of a stress held "
                                             r"since loading .* it is -1e\+99 at t = 2$"):
            solve_dimensionless(1.0, 0.1, 0.0, [1.0, 2.0, 5.0], kernel=constant(1e99),
                                force=1.0, moment=0.0, method=method)
    # 0.6 per unit time: the compliance 1 - 0.6 (t - 1) passes zero at t = 8/3
    with pytest.raises(ValueError, match=r"it is -1\.4 at t = 5$"):
        solve_dimensionless(1.0, 0.1, 0.0, [1.0, 2.0, 5.0], kernel=constant(0.6), force=1.0,
                            moment=0.0)
    # a compliance through zero at an output time the solve's inputs did not sample (16
    # of 100): the default engine, which reads it at every time, refuses it too
    times = np.linspace(1.0, 100.0, 100)

    def at_t2(t, tau):
        return np.where(np.abs(np.asarray(t) - times[1]) < 1e-9, 5.0, 0.0) + 0.0 * tau

    with pytest.raises(ValueError, match=r"^kernel: .* it is -4 at t = 2$"):
        solve_dimensionless(1.0, 0.1, 0.0, times, kernel=at_t2, force=1.0, moment=0.0)
    # the default engine declines it as it declines any grid it cannot resolve (with the
    # engine left to the solver, the next one answers, unconverged: ~5 s)
    with pytest.raises(UnresolvedOperator, match="does not resolve"):
        solve_dimensionless(1.0, 0.1, 0.0, [1.0, 2.0], kernel=constant(-1e50), force=1.0,
                            moment=0.0, tol=1e-6, method="nystrom")


@pytest.mark.parametrize("load", [
    {"kind": "ramp", "start": 0.0, "end": 5e5, "duration": 0.1},
    {"kind": "step", "values": [2.5e5, 5e5], "breaks": [0.1]},
])
def test_a_jump_before_the_first_output_time_is_marched(load: dict) -> None:
    """The march starts at loading, and a ramp or step ending before the first output
    time was dropped from the times it lands on: the answer was that of a step at
    loading, 1e-3 off at tol 1e-6 with no flag (a review). Now it equals the answer
    with output times before it too (measured: the same to the last digit)."""
    from core.presets import read_preset
    from core.scene import solve

    scene = read_preset("uniform_flat")
    scene["loading"]["force"] = load
    late = solve(dict(scene, times=[1.0, 10.0, 100.0, 365.0]))
    full = solve(dict(scene, times=[0.0, 0.05, 0.2, 0.5, 1.0, 10.0, 100.0, 365.0]))
    np.testing.assert_allclose(late.settlement, full.settlement[-4:], rtol=1e-6)


def test_a_narrow_pulse_written_as_a_formula_is_marched() -> None:
    """A five-hour pulse of half the force as a formula (``expr``) fell between the steps
    of every grid: the steady force's answer, 8.6e-5 off at tol 1e-6, success and no flag,
    where the same pulse as a ``bump`` (whose centre and widths are landing points) was
    answered. A formula's narrow extremes among 2 x 4097 samples, and samples up to 16
    away either side, are now landing points (``formula_features``): the two answers
    agree to 1.3e-9 (measured; each is within tol of the truth, so within 2 tol)."""
    from core.presets import read_preset
    from core.scene import scene_from_dict, solve
    from core.scene.dimensionless import formula_features

    scene = read_preset("eccentric_creep")
    scene["times"] = {"end": 365.0, "count": 6, "spacing": "linear"}
    scene["solver"]["tol"] = 1e-6
    force = float(scene["loading"]["force"])
    answers = {}
    for kind, load in (
            ("bump", {"kind": "bump", "mean": force, "amplitude": 0.5 * force,
                      "center": 101.3, "width": 0.2}),
            ("expr", {"kind": "expr",
                      "expr": f"{force} + {0.5 * force} * exp(-((t - 101.3) / 0.2)^2)"})):
        scene["loading"]["force"] = load
        answers[kind] = solve(scene)
        assert answers[kind].info["success"], answers[kind].info["message"]
    np.testing.assert_allclose(answers["expr"].settlement, answers["bump"].settlement,
                               rtol=2e-6, atol=0)
    np.testing.assert_allclose(answers["expr"].tilt, answers["bump"].tilt, rtol=2e-6, atol=0)
    # a smooth formula has no landing points of its own, a smooth wave neither (each of
    # its crests made eleven: 2380 steps instead of 796 for the same answer, a review),
    # nor one oscillating many times
    smooth = dict(scene, loading={"force": {"expr": "5e5 + 1e3 * t"}, "moment": 0.0})
    wave = dict(scene, loading={"force": {"expr": "5e5 * (1 + 0.2 * sin(6.2832 * t / 40))"},
                                "moment": 0.0})
    wavy = dict(scene, loading={"force": {"expr": "5e5 * (1 + 0.1 * sin(t))"},
                                "moment": 0.0})
    for name, case in (("smooth", smooth), ("wave", wave), ("wavy", wavy)):
        load = scene_from_dict(case).loading["force"]
        assert formula_features(load, 365.0) == (), name


def test_a_pulse_through_the_rows_of_a_smooth_table_is_marched() -> None:
    """A three-day pulse of the force (5e5 -> 1e6 -> 5e5 N/m) as a pchip table was
    stepped over: the answer of the constant force, 2 % off at tol 1e-6, no flag (a
    review). A table's rows are now landing points of the time steps: the settlement
    after it is 1.97 % above the constant force's, and 3.2e-6 from the linear table's
    through the same rows (the two shapes differ between the rows), as measured."""
    from core.presets import read_preset
    from core.scene import solve

    scene = read_preset("uniform_flat")
    scene["times"] = {"end": 365.0, "count": 40, "spacing": "linear"}
    rows = [[0.0, 5e5], [188.25, 5e5], [189.6, 1e6], [191.0, 5e5], [365.0, 5e5]]
    answers = {}
    for kind in ("pchip", "linear"):
        scene["loading"]["force"] = {"kind": "table", "interpolation": kind, "points": rows}
        answers[kind] = solve(scene)
    scene["loading"]["force"] = 5e5
    constant = solve(scene)
    after = int(np.searchsorted(constant.times, 192.0))
    pulse = answers["pchip"].settlement[after] / constant.settlement[after] - 1
    assert pulse > 0.01, pulse
    assert answers["pchip"].settlement[after] == pytest.approx(
        answers["linear"].settlement[after], rel=1e-3)
