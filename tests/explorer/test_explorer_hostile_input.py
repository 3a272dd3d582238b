"""Hostile and broken input to the explorer, without a browser: markup typed by a user, in a
link, a scene file, an uploaded table or a solver's message reaches the page as text;
uploads and links over the limits are refused with a notice and the result on screen
stays; the server listens on localhost unless told otherwise."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from core.scene import MAX_SCENE_BYTES
from explorer.model.links import MAX_JSON, PREFIX, decode_scene, encode_scene
from tests.conftest import base_scene, edited

XSS = ['<script>window.__xss = 1</script>', '<img src=x onerror="window.__xss=1">',
       "<img src=x onerror=alert(1)>"]


def _rendered_markup(app: Any) -> list[str]:
    """The markup of every HTML and Markdown pane on the page (what the browser renders)."""
    import panel as pn

    texts = []
    page = app.__panel__()  # (every tab filled, as shown)
    for pane in page.select(pn.pane.Markdown) + page.select(pn.pane.HTML):
        texts.append(str(pane.object))
    texts += [str(app.results.notice_alert.object), str(app.results.alert.object)]
    return texts


def assert_inert(app: Any) -> None:
    for text in _rendered_markup(app):
        lowered = text.lower()
        assert "<script" not in lowered and "<img" not in lowered, text
        assert "onerror=" not in lowered or "&lt;" in lowered, text


def test_markup_in_a_link_is_shown_as_text(explorer_app) -> None:
    scene = base_scene()
    scene["name"] = XSS[0]
    scene["description"] = XSS[1]
    scene["punch"][XSS[2]] = 1.0
    app = explorer_app(query={"scene": encode_scene(scene)})
    assert "unknown field" in app.screen.notice and "default scene" in app.screen.notice
    assert "&lt;img src=x onerror=alert(1)&gt;" in app.results.notice_alert.object
    assert_inert(app)
    app = explorer_app(query={"preset": XSS[1]})
    assert "Unknown preset" in app.screen.notice
    assert_inert(app)


def test_markup_in_scene_files_and_fields_is_shown_as_text(explorer_app) -> None:
    app = explorer_app()
    good = base_scene()
    good["name"] = XSS[0]
    good["description"] = XSS[1]
    app.files_tab.load_file.filename = "scene.json"
    app.files_tab.load_file.value = json.dumps(good).encode()
    assert app.screen.notice == "" and app.state.scene_name == XSS[0]
    saved = app.files_tab.save_scene.filename
    assert "<" not in saved and "/" not in saved
    assert_inert(app)
    # the core echoes these texts in its messages
    for bad in (edited("base.creep", {"model": XSS[1], "modulus": 3e10}),
                edited("punch.shape", {"expr": "sin(x) + " + XSS[2]}),
                edited("punch.shape", {"kind": XSS[0]}),
                edited("loading.force", {"kind": "table", XSS[2]: 1})):
        app.files_tab.load_file.filename = XSS[1] + ".json"
        app.files_tab.load_file.value = json.dumps(bad).encode()
        assert app.screen.notice.startswith("The scene was not loaded"), app.screen.notice
        assert_inert(app)
    app.files_tab.load_file.value = b"{" + XSS[2].encode()
    assert "not valid JSON" in app.screen.notice
    assert_inert(app)
    # a value typed into the name field
    app.files_tab.scene_name.value = XSS[0]
    assert_inert(app)


def test_markup_in_an_uploaded_table_is_shown_as_text(explorer_app) -> None:
    app = explorer_app()
    app.punch_tab.shape_file.filename = XSS[1] + ".csv"
    app.punch_tab.shape_file.value = ("x,f\n-0.5,0\n0," + XSS[2] + "\n").encode()
    assert app.screen.notice.startswith("The shape table was not used: Punch, shape (punch.shape): "
                                 "line 3, column 2:"), app.screen.notice
    assert_inert(app)
    app.punch_tab.shape_file.value = b"x,f\n-0.5,0.00002\n0,0\n0.5,0.00001\n"
    assert app.state.punch.shape == "custom" and app.screen.notice == ""
    assert "&lt;img" in app.punch_tab.shape_note.object
    assert_inert(app)


def test_markup_in_a_solver_message_is_shown_as_text(explorer_app) -> None:
    """A valid file whose creep formula fails at solve time: the alert escapes it."""
    app = explorer_app()
    shown = app.controller.view
    app.state.base.param.update(creep_model="custom", custom={
        "model": "kernel", "modulus": 3e10, "expr": "0.01 * exp(-(t - tau))"})
    assert app.results.alert.visible and "base.creep.expr" in app.results.alert.object
    assert app.controller.view is shown
    app.controller.param.update(error="solve: " + XSS[1])
    assert_inert(app)


def test_uploads_over_the_limits_are_refused_with_a_notice(explorer_app) -> None:
    app = explorer_app()
    shown = app.controller.view
    app.files_tab.load_file.filename = "big.json"
    app.files_tab.load_file.value = b" " * (MAX_SCENE_BYTES + 1)
    assert "too large" in app.screen.notice and str(MAX_SCENE_BYTES) in app.screen.notice
    app.files_tab.load_file.filename = "deep.json"
    app.files_tab.load_file.value = b"[" * 100_000 + b"]" * 100_000
    assert "nested too deeply" in app.screen.notice
    app.punch_tab.shape_file.filename = "big.csv"
    app.punch_tab.shape_file.value = b"x,f\n" + b"0.0,0.0\n" * 200_000
    assert "punch.shape" in app.screen.notice and "too large" in app.screen.notice
    app.punch_tab.shape_file.filename = "rows.csv"
    rows = "".join(f"{k / 20000 - 0.25},0\n" for k in range(10_001))
    app.punch_tab.shape_file.value = rows.encode()
    assert "too many rows" in app.screen.notice
    assert app.controller.view is shown and app.controller.error == ""


def test_an_uploaded_scene_is_read_as_strictly_as_the_command_line_reads_it(explorer_app) -> None:
    """A field given twice is refused (json.loads would silently keep the second), as are
    text that is not UTF-8 and numbers beyond any double; the result on screen stays."""
    app = explorer_app()
    shown = app.controller.view
    text = json.dumps(base_scene())
    app.files_tab.load_file.filename = "twice.json"
    app.files_tab.load_file.value = text.replace('"name":', '"name": "first", "name":', 1).encode()
    assert app.screen.notice == "The file 'twice.json': duplicate field 'name' in one JSON object"
    app.files_tab.load_file.filename = "latin1.json"
    app.files_tab.load_file.value = b'{"name": "caf\xe9"}'  # Latin-1
    assert "not text in UTF-8" in app.screen.notice
    app.files_tab.load_file.filename = "huge.json"
    app.files_tab.load_file.value = text.replace(
        '"schema_version": 1', '"schema_version": ' + "9" * 500, 1).encode()
    assert app.screen.notice.startswith("The scene was not loaded"), app.screen.notice
    assert app.controller.view is shown and app.controller.error == ""


def test_an_uploaded_table_with_too_many_rows_for_the_solver_keeps_the_last_result(
        explorer_app) -> None:
    app = explorer_app()
    shown = app.controller.view
    rows = "".join(f"{x:.4f},{1e-5 * (1 + np.sin(20 * x)):.3e}\n"
                   for x in np.linspace(-0.9, 0.9, 40))
    app.punch_tab.shape_file.filename = "measured.csv"
    app.punch_tab.shape_file.value = ("x,f\n" + rows).encode()
    # every row of a linear table is a kink, the end rows too (the held value begins):
    # more than the solver allows, so the upload itself is refused, naming the limit
    assert app.state.punch.shape == "flat"
    assert "(punch.shape): a table of 40 rows" in app.screen.notice and "16" in app.screen.notice
    assert app.controller.view is shown


def test_a_deeply_nested_link_is_refused(explorer_app) -> None:
    import base64
    import zlib

    raw = b'{"a":' + b"[" * 90_000 + b"]" * 90_000 + b"}"
    assert len(raw) < MAX_JSON
    link = PREFIX + base64.urlsafe_b64encode(zlib.compress(raw, 9)).decode().rstrip("=")
    with pytest.raises(ValueError, match="nested too deeply"):
        decode_scene(link)
    app = explorer_app(query={"scene": link})
    assert "nested too deeply" in app.screen.notice and app.controller.view is not None


def test_the_server_listens_on_localhost_unless_told(monkeypatch) -> None:
    import explorer.__main__ as entry

    served: list[dict[str, Any]] = []  # the options pn.serve would be given
    monkeypatch.setattr(entry, "_serve", lambda pn, apps, **k: served.append(k))
    # (the server's switch of Bokeh's diagnostics would outlast this test in the process)
    monkeypatch.setattr(entry, "quiet_bokeh_diagnostics", lambda: None)
    base = ["--port", "5999", "--warm-up", "none", "--solver-processes", "0"]
    assert entry.main(base) == 0
    assert served[-1]["address"] == "localhost" and served[-1]["websocket_origin"] is None
    assert entry.main([*base, "--address", "0.0.0.0"]) == 0
    origins = served[-1]["websocket_origin"]
    assert served[-1]["address"] == "0.0.0.0" and "localhost:5999" in origins
    assert entry.main([*base, "--address", "0.0.0.0",
                       "--allow-websocket-origin", "lab.example.org:80"]) == 0
    assert served[-1]["websocket_origin"] == ["lab.example.org:80"]
    count = len(served)
    assert entry.main([*base[:-1], "-1"]) == 2  # --solver-processes -1: refused, not served
    assert len(served) == count


def test_the_live_bound_of_the_server_reaches_every_session(monkeypatch, explorer_app) -> None:
    """``--live-bound``: the CPU time of a solve under which sliders that otherwise wait
    for their release follow a drag (default ``explorer.app.LIVE_SOLVE_S``)."""
    import explorer.__main__ as entry
    from explorer.app import LIVE_BOUND_LIMITS_S, LIVE_SOLVE_S, create_app
    from explorer.views import eccentricity

    shown = " ".join(entry.build_parser().format_help().split())
    assert f"(default {LIVE_SOLVE_S:g}:" in shown
    assert f"keeps its own {eccentricity.LIVE_SOLVE_S:g})" in shown
    assert "this, {:g} to {:g} (default".format(*LIVE_BOUND_LIMITS_S) in shown
    served: list[dict[str, Any]] = []  # the apps pn.serve would be given
    monkeypatch.setattr(entry, "_serve", lambda pn, apps, **k: served.append(apps))
    monkeypatch.setattr(entry, "quiet_bokeh_diagnostics", lambda: None)
    base = ["--port", "5999", "--warm-up", "none", "--solver-processes", "0"]
    assert entry.main(base) == 0 and served[-1]["app"] is create_app
    made: list[dict[str, Any]] = []
    monkeypatch.setattr("explorer.app.create_app", lambda **k: made.append(k))
    assert entry.main([*base, "--live-bound", "0.5"]) == 0
    served[-1]["app"]()  # as the server does for each page
    assert made == [{"live_bound": 0.5}]
    for bad in ("0", "-1", "61", "nan"):
        assert entry.main([*base, "--live-bound", bad]) == 2
    assert len(served) == 2
    # a session decides on its own bound: the default scene's last solve took some CPU
    app = explorer_app(solved=True)
    spent = app.controller.view.info["cpu_seconds"]
    assert app.fast_solves() == (spent < LIVE_SOLVE_S)
    app.live_bound = 2 * spent
    assert app.fast_solves()
    app.live_bound = 0.5 * spent
    assert not app.fast_solves()
    for bad in (-1.0, 0.0, 61.0, float("nan"), float("inf"), True, "0.1"):
        with pytest.raises(ValueError, match="live_bound: must be a number of seconds from "
                                             "0.001 to 60, got"):
            explorer_app(live_bound=bad)


def test_an_empty_file_is_said_and_not_taken_for_the_one_before(explorer_app) -> None:
    """An empty scene file was taken silently (a green "Upload complete" and nothing
    else), leaving an earlier refusal naming another file on screen; an empty table was
    too. A truncated file read "starting at at line 1" (a teacher's audit)."""
    app = explorer_app()
    shown = app.controller.view
    app.files_tab.load_file.filename = "notes.json"
    app.files_tab.load_file.value = b'{"name": "x'
    assert app.screen.notice == ("The file 'notes.json': not valid JSON (Unterminated "
                                 "string starting at line 1, column 10)")
    app.files_tab.load_file.filename = "empty.json"
    app.files_tab.load_file.value = b""
    assert app.screen.notice == ("The file 'empty.json': the file is empty (a scene file is "
                                 "a JSON object)")
    app.punch_tab.shape_file.filename = "empty.csv"
    app.punch_tab.shape_file.value = b""
    assert "punch.shape" in app.screen.notice and "empty" in app.screen.notice
    assert app.controller.view is shown and app.controller.error == ""


def test_a_table_dropped_again_after_another_is_the_one_taken(explorer_app) -> None:
    """The dropper keeps every file dropped in one dict, in the order first dropped: a
    history table dropped a second time, after another, was read as that other one (the
    page went on saying "Custom history from hist_nohdr.csv": an audit). The dropper's
    own events (Panel's FileDropper._process_event, one chunk each) drive it here."""
    from types import SimpleNamespace

    app = explorer_app()
    force = app.state.loading.histories["force"]
    force.kind = "custom"
    editor = app.scene_tab.history_editors[0]
    dropper = editor.upload._box

    def drop(name: str, text: str) -> None:
        dropper._process_event(SimpleNamespace(event_name="upload_event", data={
            "name": name, "chunk": 1, "total_chunks": 1, "type": "text/csv",
            "data": text.encode()}))

    drop("first.csv", "0,300000\n365,300000\n")
    drop("second.csv", "0,400000\n365,400000\n")
    drop("first.csv", "0,500000\n365,500000\n")     # the first name, dropped again
    assert "from first.csv" in editor.note.object, editor.note.object
    assert force.custom["points"] == [[0.0, 500000.0], [365.0, 500000.0]]
