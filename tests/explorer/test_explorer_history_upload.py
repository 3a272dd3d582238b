"""The "custom (from file)" load history offers a table upload (explorer/views/widgets.py,
HistoryEditor): a CSV of t [days] and the load [SI] becomes the history the solve uses."""

from __future__ import annotations

import numpy as np

from core.presets import read_preset
from core.scene import solve
from explorer.model import ExplorerState
from explorer.views.widgets import HistoryEditor


def _editor() -> tuple[ExplorerState, HistoryEditor]:
    state = ExplorerState()
    state.load_scene(read_preset("uniform_flat"))  # creep, 40 output times
    history = state.loading.histories["force"]
    editor = HistoryEditor("load-0")
    editor.bind(history, state.time_end)
    return state, editor


def test_custom_history_offers_an_upload_and_the_table_is_solved():
    state, editor = _editor()
    assert editor.upload is None  # no file box until it is asked for
    history = state.loading.histories["force"]
    history.kind = "custom"
    assert editor.upload is not None and editor.upload.visible
    assert "t [days after loading]" in editor.upload_help.object
    assert "[N/m]" in editor.upload_help.object
    end = state.time_end
    table = f"t,force\n0,200000\n{end / 2:g},400000\n{end:g},400000\n".encode()
    editor.upload.param.update(filename="ramp.csv", value=table)
    assert history.kind == "custom" and history.custom["kind"] == "table"
    assert "ramp.csv" in editor.note.object
    result = solve(state.to_scene())
    # the given force is the table's, linear between its rows [N/m] (to rounding: the
    # scalings to the dimensionless problem and back)
    wanted = np.interp(result.times, [0.0, end / 2, end], [2e5, 4e5, 4e5])
    assert np.allclose(result.force, wanted, rtol=1e-12, atol=0.0)
    history.kind = "constant"
    assert not editor.upload.visible


def test_a_bad_table_is_refused_in_the_editor_and_the_history_is_kept():
    state, editor = _editor()
    history = state.loading.histories["force"]
    history.kind = "custom"
    before = history.custom
    editor.upload.param.update(filename="bad.csv", value=b"t,force\n0,1\n0,2\n")
    assert history.custom == before
    assert "The table was not used: loading.force" in editor.note.object
