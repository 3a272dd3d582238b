"""The explorer served by Panel's own server (``panel serve`` or ``pn.serve`` of
``explorer.create_app``), not by ``python -m explorer``.

``python -m explorer`` turns Bokeh's error diagnostics off (``quiet_bokeh_diagnostics``),
and with them its check of every callback's signature. A session-end callback whose
parameter Bokeh did not accept (``idle_release.session_closed`` with a default value)
failed that check in every other server: each page was Panel's error pane (7 models,
"ValueError: Callback functions must have signature func(session_context)"), while the
suite, serving through ``python -m explorer``, saw nothing.
"""

from __future__ import annotations

import time

import panel as pn
import pytest
from bokeh.client import pull_session
from bokeh.models import Markup
from bokeh.settings import settings

from tests.support.serving import free_port


@pytest.mark.slow
def test_a_page_served_by_panel_with_bokehs_diagnostics_on_is_the_explorer() -> None:
    from explorer import create_app

    assert settings.perform_error_diagnostics()   # Bokeh's default, here as in any server
    port = free_port()
    server = pn.serve({"app": create_app}, port=port, address="127.0.0.1", show=False,
                      threaded=True)
    try:
        # (the server's thread listens a moment after it starts)
        deadline = time.monotonic() + 60.0
        while True:
            try:
                session = pull_session(url=f"http://127.0.0.1:{port}/app")
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        with session:
            models = list(session.document.models)
    finally:
        server.stop()
    texts = " ".join(m.text for m in models if isinstance(m, Markup))
    assert "Traceback" not in texts and "must have signature" not in texts
    # the explorer's page (hundreds of models, its heading), not an error pane
    assert len(models) > 100 and "Coated punch explorer" in texts
