"""Shared fixtures and scenes of the test suite.

- No state leaks between tests: mpmath's working precision is restored after every test
  (a test that needs more digits uses ``mpmath.workdps``), and stage evaluations are
  counted from a fixture that starts from empty stage caches (:func:`stage_evaluations`),
  so a count does not depend on which tests ran before; a test that looks at what the
  caches hold asks for :func:`cold_caches`.
- Tests wait on conditions, never on the clock: :func:`wait_until` polls a condition and
  returns False when a generous bound runs out (a failure bound, not a measurement),
  stretched on a busy machine; so is a test's hard limit (its ``timeout`` marker).
- Property tests draw the same examples on every run (hypothesis profile ``suite``,
  derandomized); ``HYPOTHESIS_PROFILE=explore`` draws new ones.
- One served explorer (:func:`explorer_server`, ``python -m explorer`` in a child
  process) serves the browser tests of a run (but for the few modules that need a server
  of their own, ``tests.support.probe.own_explorer_server``): each test opens its own
  page (a session of its own), and each browser module checks the server's output
  written while it ran (tests/browser_pages.py). Starting a server costs a warm-up solve
  and its solver processes; once per run instead of once per module.
- The command line runs in the test's own process (``run_cli`` of tests/cli_runs.py:
  ``core.cli.main`` with stdout and stderr captured): a child process costs ~1 s of
  imports each and tests nothing more, except the entry point itself, which a few tests
  run for real (``run_cli(..., subprocess=True)``).
- Scenes: the dimensionless benchmark problems come from ``tests/support/scenes.py`` (one
  definition for the benchmarks and the tests); :func:`small_preset` is a preset of the
  explorer cut to a few output times, for tests that need a quick real solve. Scene dicts
  written by hand start from here too (imported from ``tests.conftest``): a scene file
  (:func:`scene_file`), the small scenes the refusal tests share (:func:`base_scene`,
  :func:`elastic_dict`) and a field set or removed by its dotted path (:func:`edited`).
- Explorer sessions without a server are built by one builder, :func:`explorer_app`
  (``explorer_app()``, ``explorer_app("worn_coating", solved=True)``): a session as a
  script or a notebook runs it, solving in the test's own thread.
"""

from __future__ import annotations

import copy
import json
import math
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import mpmath
import pytest
from hypothesis import settings

from tests.support import scenes as benchmark_scenes

# The suite draws the same examples on every run, so it cannot flake on a rare draw;
# HYPOTHESIS_PROFILE=explore draws new ones when digging by hand.
settings.register_profile("suite", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "suite"))


def wait_until(condition: Callable[[], Any], timeout: float = 30.0,
               every: float = 0.02) -> bool:
    """True as soon as ``condition()`` is true; False if it is not within ``timeout`` [s]
    (on a quiet machine; stretched on a busy one: :func:`tests.browser_pages.patience`)."""
    from tests.browser_pages import patience

    deadline = time.monotonic() + timeout * patience()
    while True:
        if condition():
            return True
        if time.monotonic() >= deadline:
            return False
        time.sleep(every)


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    """A test's hard time limit (its ``timeout`` marker, pytest-timeout) stretched as its
    waits are (:func:`tests.browser_pages.patience`, read when the test starts): the
    limit catches a test that hangs, it does not time the machine. On a 2-core machine
    running the suite beside a CPU hog (load ~6) the browser test of the FE coating
    check ran out of its fixed 300 s while its own wait for the check, 180 s stretched,
    still had time."""
    from tests.browser_pages import patience

    marker = item.get_closest_marker("timeout")
    seconds = None if marker is None else (marker.args[0] if marker.args
                                           else marker.kwargs.get("timeout"))
    if isinstance(seconds, (int, float)) and seconds > 0:
        # first among the item's markers: the closest one, which pytest-timeout reads
        item.add_marker(pytest.mark.timeout(float(seconds) * patience()), append=False)
    yield


@pytest.fixture(name="wait_until")
def wait_until_fixture() -> Callable[..., bool]:
    """:func:`wait_until` for the tests: ``assert wait_until(lambda: done, timeout=60)``."""
    return wait_until


@pytest.fixture(autouse=True)
def _mpmath_precision_restored() -> Iterator[None]:
    saved = mpmath.mp.prec
    yield
    mpmath.mp.prec = saved


@pytest.fixture(autouse=True)
def _pages_released() -> Iterator[None]:
    """The explorer pages a test built are let go when it ends, as the server lets go of
    a closed session's page (``explorer.fixes.closed_pages.page_releaser``): Panel's link
    registry holds every page whose widgets are linked, for good (a dictionary weak in
    its keys whose values hold their keys), and nothing of a session ends a test's page.
    Kept, the pages of the ~300 explorer tests (~100,000 objects each) stayed in the
    process for the rest of the run: the oldest generation of the collector grew to
    millions of objects, and its collections took 56 s of the explorer tests' 310 s of
    CPU (a ``gc.callbacks`` timer). A page frozen out of the collector's reach
    (``explorer.fixes.gc_policy``, served pages that the tests stand in for) is given
    back to it too."""
    import gc
    import sys

    links = sys.modules.get("panel.links")
    before = set(links.Callback.registry.keyrefs()) if links is not None else set()
    yield
    links = sys.modules.get("panel.links")
    if links is not None:
        registry = links.Callback.registry
        for ref in [ref for ref in registry.keyrefs() if ref not in before]:
            owner = ref()
            if owner is not None:
                registry.pop(owner, None)
    if gc.get_freeze_count():
        gc.unfreeze()


@pytest.fixture
def cold_caches() -> None:
    """Empty stage caches when the test begins: the caches are process-wide, so what a test
    then finds cached is what its own solves put there, whatever ran before it."""
    from core.cache import clear_caches

    clear_caches()


@pytest.fixture
def stage_evaluations(cold_caches: None) -> Callable[[], dict[str, int]]:
    """Evaluations of each solver stage since the test began, from empty stage caches
    (:func:`cold_caches`): a test's counts are those of its own solves."""
    from core.cache import stage_counts

    start = stage_counts()

    def since_start() -> dict[str, int]:
        return {name: count - start.get(name, 0) for name, count in stage_counts().items()}

    return since_start


@pytest.fixture(scope="session")
def scenes() -> Any:
    """The benchmark problems' module (``tests/support/scenes.py``): ``smooth_m``,
    ``jump_m``, ``stepped_g``, ``CONCRETE``, ``suite()`` ..."""
    return benchmark_scenes


def small_preset_scene(key: str | None = None, count: int = 6, tol: float = 1e-5,
                       force_kN: float | None = None) -> dict[str, Any]:
    """A preset of the explorer (the default one if ``key`` is None) with ``count`` output
    times over 200 days, tolerance ``tol`` and, if given, a constant force [kN/m]."""
    from explorer.model import DEFAULT_PRESET, presets

    scene = copy.deepcopy(presets()[key or DEFAULT_PRESET])
    scene["times"] = {"end": 200.0, "count": count, "spacing": "log"}
    scene["solver"] = {"tol": tol}
    if force_kN is not None:
        scene["loading"]["force"] = {"kind": "constant", "value": force_kN * 1e3}
    return scene


@pytest.fixture(name="small_preset")
def small_preset_fixture() -> Callable[..., dict[str, Any]]:
    """:func:`small_preset_scene` for the tests."""
    return small_preset_scene


SCENES_DIR = Path(__file__).resolve().parent.parent / "core" / "presets" / "scenes"


def scene_file(name: str) -> dict[str, Any]:
    """The scene file ``core/presets/scenes/<name>.json`` as a new dict."""
    return json.loads((SCENES_DIR / f"{name}.json").read_text())


def base_scene() -> dict[str, Any]:
    """A small valid scene (few output times: its solves stay quick)."""
    scene = scene_file("uniform_flat")
    scene["times"] = {"end": 100.0, "count": 3, "spacing": "linear"}
    scene["solver"] = {"tol": 1e-3}
    return scene


def elastic_dict(**changes: Any) -> dict[str, Any]:
    """The uniform preset on an elastic base, few times: a solve of ~0.1 s."""
    d = scene_file("uniform_flat")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = {"end": 10.0, "count": 3}
    d.update(changes)
    return d


class _Delete:
    """The type of :data:`DELETE`: its name in test ids is the same in every process (an
    ``object()`` is named by its address, and the processes of the suite would collect
    different tests)."""

    def __repr__(self) -> str:
        return "DELETE"


#: The value :func:`edited` reads as "remove the field".
DELETE = _Delete()


def edited(path: str, value: Any, scene: dict[str, Any] | None = None) -> dict[str, Any]:
    """``scene`` (default :func:`base_scene`) with the field at dotted ``path`` set to
    ``value``, or removed when ``value`` is :data:`DELETE`."""
    scene = base_scene() if scene is None else scene
    *parents, last = path.replace("[", ".").replace("]", "").split(".")
    target: Any = scene
    for key in parents:
        target = target[int(key)] if key.isdigit() else target[key]
    if value is DELETE:
        del target[last]
    elif last.isdigit():
        target[int(last)] = value
    else:
        target[last] = value
    return scene


def write_scene(path: Path, d: dict[str, Any] | None = None) -> Path:
    """``d`` (default :func:`elastic_dict`) written as a scene file at ``path``."""
    path.write_text(json.dumps(d or elastic_dict()))
    return path


#: Values no number, string or choice field should take without a clear refusal.
ODD = [math.nan, math.inf, -math.inf, "x", None, True, [[1]], {"a": 1}, 10**400,
       "__import__('os').system('true')", 1e308]


@pytest.fixture(scope="session")
def explorer_server() -> Iterator[Any]:
    """The served explorer of the browser tests (``tests.support.serving.ExplorerProcess``,
    default options, one BLAS thread): started when a test first asks, stopped at the end
    of the run."""
    from tests.support.serving import browser_test_server

    with browser_test_server() as explorer:
        yield explorer


def build_explorer_app(preset: str | None = None, *, solved: bool = False,
                       **kwargs: Any) -> Any:
    """An explorer session without a server (``explorer.app.ExplorerApp``).

    ``preset``: the preset it starts from (default: the default scene, or ``scene=``);
    ``solved``: wait for its first result and check that the scene was solved. Solves run
    in the calling thread (``executor=None``) unless ``executor`` is given; the other
    keywords go to ``ExplorerApp`` (``scene``, ``query``, ``solve``)."""
    from explorer.app import ExplorerApp
    from explorer.model import presets

    kwargs.setdefault("executor", None)
    if preset is not None:
        kwargs["scene"] = presets()[preset]  # a copy of its own
    app = ExplorerApp(**kwargs)
    if solved:
        assert app.controller.wait(120) and app.controller.error == "", app.controller.error
    return app


@pytest.fixture(name="explorer_app")
def explorer_app_fixture() -> Callable[..., Any]:
    """:func:`build_explorer_app` for the tests."""
    return build_explorer_app


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Cancel the solves the explorer tests left queued on the shared pool.

    The pool's threads are joined when the interpreter exits, so the queued solves of
    sessions the tests dropped would otherwise all run before the process ends.
    """
    import sys

    solving = sys.modules.get("explorer.solving")
    if solving is not None:
        solving.shared_pool().shutdown(wait=False, cancel_futures=True)

