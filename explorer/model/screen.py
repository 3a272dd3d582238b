"""What the page shows now: the result drawn, the output time shown, and a notice."""

from __future__ import annotations

import param

from .results import ResultView

#: How the notice of a refused value begins.
REFUSED = "Value not accepted: "


class Screen(param.Parameterized):
    """The session's screen, shared by its views: the result on screen (what downloads,
    the check, the report and the link hold), the output time shown, a notice, the
    latest FE check of the coating model and the latest fit."""

    notice = param.String(default="", doc="A problem with a file or a link (not a solve).")
    time_index = param.Integer(default=0, doc="Index of the output time shown.")
    model_check = param.Dict(default=None, allow_None=True, doc=(
        "The latest FE check of the coating model (core.scene.check_scene's report): "
        "where it was made for the scene on screen, its measured error is the one the "
        "badges, the status and the report speak of (core.scene.model_error_evidence)."))

    fit = param.Parameter(default=None, doc=(
        "The latest back-analysis of the Fit tab (a FitOutcome): while its fitted scene is "
        "the one on screen, the printable report carries it."))

    def __init__(self, **params: object) -> None:
        super().__init__(**params)
        #: the result drawn (None until the first one); set by the page as it draws
        self.drawn: ResultView | None = None

    def shown(self) -> ResultView | None:
        """The result on screen."""
        return self.drawn

    def reject(self, message: str) -> None:
        """Say on the page that a value typed or dragged was refused, and why."""
        self.notice = f"{REFUSED}{message}"

    def scene_changed(self) -> None:
        """A change of the scene was taken (a value typed again, a step, an undo, a reset,
        a preset): a refusal on screen is over (it read "it stays 500" beside P = 600)."""
        self.accepted()

    def accepted(self) -> None:
        """A value typed was taken (a change of the scene, a limit of the check): a
        refusal on screen is over (a refused limit's "the limit stays 2000" stayed up for
        minutes beside the limits typed after it, an engineer's audit found)."""
        if self.notice.startswith(REFUSED):
            self.notice = ""
