"""An emptied number box shown empty, not as "NaN".

Panel (checked with 1.9.4) sends a ``FloatInput`` whose value is None to the page as NaN
(``FloatInput._process_param_change``), which BokehJS's number input then shows as the
text "NaN": a box the explorer empties (a limit left unset, a refused value put back to
"not set") read "NaN". BokehJS's number input takes null for an empty box; the fix sends
None as null. Values from the page are read as before (NaN from an emptied box becomes
None in Python).
"""

from __future__ import annotations

import logging
import math
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False
_EMPTY = ("value", "value_throttled")


def install() -> bool:
    """Wrap Panel's conversion once per process; False if Panel's internals differ."""
    global _INSTALLED
    if _INSTALLED:
        return True
    from panel.widgets.input import FloatInput

    original = FloatInput.__dict__.get("_process_param_change")
    if original is None:
        log.warning("Panel's FloatInput has changed; empty boxes may show NaN")
        return False

    def process_param_change(self: Any, params: dict[str, Any]) -> dict[str, Any]:
        empty = [name for name in _EMPTY if name in params and params[name] is None]
        out = original(self, params)
        for name in empty:
            if isinstance(out.get(name), float) and math.isnan(out[name]):
                out[name] = None
        return out

    process_param_change.__wrapped__ = original  # type: ignore[attr-defined]
    FloatInput._process_param_change = process_param_change
    _INSTALLED = True
    return True
