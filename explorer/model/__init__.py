"""The explorer's model: what the user sets and what the page shows, in numbers and words.

Nothing here imports Panel or Bokeh: the solver workers import this package (a result is
prepared where it is solved), and the state can be used without a server.

- ``state``: :class:`ExplorerState`, the scene on screen in display units, and its parts:
  ``scene_parts`` (punch, coating layers, base), ``loading_state`` (which two quantities
  are given, and their histories), ``punches_state`` (the punches of a scene of
  several), ``code_creep_state`` (design-code creep inputs).
- ``results``: :class:`ResultView`, a solution turned into the arrays the plots show.
- ``contact_zone``: the contact zone of a result in numbers.
- ``design``: the design check against the limits the user sets.
- ``scales``: one pressure unit and colour range per scene family.
- ``pins``: pinned results, named after what differs between them.
- ``presets``, ``lessons``: the preset scenes, and lessons built from them.
- ``links``, ``view_link``: the scene, and what else a link keeps, in the page's address.
- ``undo``, ``history``: the scenes shown, for undo and reset.
- ``screen``: what the page shows now (the result, the output time, a notice).
- ``study``: the Study tab's design studies, planned from the scene on screen.
- ``fit``: the Fit tab's back-analysis: readings, the fields fitted, the outcome shown.
"""

from .code_creep_state import (
    CODE_CREEP_MODELS,
    STRENGTH_CLASSES,
    CodeCreepState,
    creep_coefficient_data,
)
from .contact_zone import (
    contact_text,
    contact_widths,
    contact_zones,
    lift_off_lengths,
    lifted_times,
    lifts_off,
    lifts_or_pulls,
)
from .design import (
    DesignLimits,
    check_html,
    design_check,
    punch_design_checks,
    punch_verdicts,
    punches_check_html,
    scene_limits,
    scene_with_limits,
    screen_limits,
    view_verdict,
)
from .fit import (
    MAX_FIT_FIELDS,
    FitOutcome,
    fit_choices,
    forecast_columns,
    plan_fit,
    read_upload,
    readings_columns,
    readings_note,
    run_fit,
)
from .history import SceneHistory
from .lessons import STEP_END, Lesson, lesson_title, lessons, step_scene
from .links import decode_scene, encode_scene
from .loading_state import QUANTITIES, QUANTITY_RANGES, QUANTITY_UNITS, STATEMENTS, HistoryState
from .pins import MAX_PINS, Pin, PinBoard, eccentricity
from .presets import DEFAULT_PRESET, ORDER, preset_label, presets
from .punches_state import SCREEN_PUNCHES, PunchEntryState, validated_scene
from .results import (
    Geometry,
    PunchResult,
    ResultView,
    load_jumps,
    model_evidence,
    prepare_view,
    shown_flags,
)
from .scales import DisplayScales
from .scene_parts import (
    CONTACT_MODELS,
    CREEP_MODELS,
    INTERFACES,
    MAX_DESCRIPTION_CHARS,
    MAX_NAME_CHARS,
    SCREEN_LAYERS,
    LayerState,
    ProfileState,
    check_text,
)
from .screen import Screen
from .state import MODEL_TOL_RANGE, MODIFIED, ExplorerState
from .study import (
    MAX_POINTS,
    OUTPUTS,
    SPACINGS,
    Axis,
    PlannedStudy,
    StudyResult,
    default_range,
    plan_study,
    study_choices,
    study_outputs,
)
from .view_link import (
    read_fit_query,
    read_study_query,
    read_view_query,
    study_settings,
    view_query,
)

__all__ = ["CODE_CREEP_MODELS", "CONTACT_MODELS", "CREEP_MODELS", "DEFAULT_PRESET", "INTERFACES",
           "MAX_DESCRIPTION_CHARS", "MAX_FIT_FIELDS", "MAX_NAME_CHARS", "MAX_PINS", "MAX_POINTS",
           "MODEL_TOL_RANGE", "MODIFIED", "ORDER", "OUTPUTS", "QUANTITIES",
           "QUANTITY_RANGES", "QUANTITY_UNITS", "SCREEN_LAYERS", "SPACINGS", "STATEMENTS",
           "STEP_END", "STRENGTH_CLASSES",
           "Axis", "CodeCreepState", "DesignLimits", "DisplayScales", "ExplorerState",
           "FitOutcome", "Geometry", "HistoryState", "LayerState", "Lesson", "Pin", "PinBoard",
           "PlannedStudy", "PunchEntryState", "PunchResult", "SCREEN_PUNCHES", "ProfileState",
           "ResultView", "SceneHistory", "Screen", "StudyResult",
           "check_html", "check_text", "contact_text", "contact_widths", "contact_zones",
           "creep_coefficient_data", "decode_scene", "default_range",
           "design_check", "eccentricity", "encode_scene", "fit_choices", "forecast_columns",
           "lesson_title", "lessons", "lift_off_lengths", "lifted_times", "lifts_off",
           "lifts_or_pulls",
           "model_evidence",
           "plan_fit", "plan_study", "punch_design_checks", "punch_verdicts", "punches_check_html",
           "read_upload", "readings_columns",
           "readings_note", "run_fit", "load_jumps", "prepare_view", "preset_label", "presets",
           "read_fit_query", "read_study_query", "read_view_query", "shown_flags", "scene_limits",
           "scene_with_limits", "screen_limits", "step_scene", "study_choices", "study_outputs",
           "study_settings", "validated_scene", "view_query", "view_verdict"]
