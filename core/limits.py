"""Every limit on the size of an input and the work one solve may cause, in one place.

The explorer is served to untrusted users, so a scene (a file, a dict, a link) must not
be able to take the machine: each limit below bounds one kind of work or memory and is
checked *before* that work is done, with a ``ValueError`` naming the field to change.
``core/SCENES.md`` ("Limits") lists each with the work it bounds. Other modules import
their limits from here (some keep a local alias under their historic name); this module
imports nothing from ``core``.

Measured figures quoted below were taken on the development machine (2 cores, shared);
they are orders of magnitude, not promises.
"""

from __future__ import annotations

# ----------------------------------------------------------------------------- text

#: Largest scene file read by ``core.scene.load_scene`` [bytes].
MAX_SCENE_BYTES = 1_000_000
#: Longest scene name [characters]: a title, shown in a page title and file names.
MAX_NAME_CHARS = 200
#: Longest scene description [characters]: the presets use under 500.
MAX_DESCRIPTION_CHARS = 5_000
#: Longest formula [characters] (also for its normal form).
MAX_FORMULA_CHARS = 500

# ----------------------------------------------------------------------------- formulas

#: Deepest nesting of a formula (parentheses, calls, exponents each add a level).
MAX_FORMULA_DEPTH = 20
#: Most parts of a formula (numbers, names, operators, calls).
MAX_FORMULA_PARTS = 200
#: Largest magnitude of an exponent that does not depend on the variables.
MAX_CONSTANT_EXPONENT = 64.0
#: Most array elements one evaluation of a formula may hold at once: the points asked
#: for times the formula's largest number of live intermediate arrays (its evaluation
#: stack). 2**24 doubles are 128 MiB. Callers with more points evaluate in blocks.
MAX_FORMULA_ELEMENTS = 2**24

# ----------------------------------------------------------------------------- profiles

#: Most rows of a table profile (and most breaks of a step profile).
MAX_TABLE_ROWS = 10_000
#: Largest CSV table accepted for a profile [bytes].
MAX_TABLE_BYTES = 1_000_000
#: Most coefficients of a polynomial profile (degree 15).
MAX_POLYNOMIAL_COEFFICIENTS = 16
#: Most points of (-a, a) where an x-profile's value or slope jumps, over the whole
#: scene: each adds ~140 quadrature nodes to a dense operator (16: 2448 nodes, 1.9 s,
#: 360 MB; 40: 9 s, 1.7 GB).
MAX_BREAKPOINTS = 16
#: Most punches of one scene (``punches``): the coupled system is dense over all their
#: nodes (8 punches of ~300 nodes: a 2400^2 LU, ~0.4 s and 46 MB).
MAX_PUNCHES = 8

# ----------------------------------------------------------------------------- geometry

#: Smallest accepted a/H (the paper's lam), for scenes and the solver alike.
MIN_LAM = 1e-4
#: Largest a/H of a scene. The quadrature resolves the layer kernel on the scale H, so the
#: nodes grow with a/H: measured 1216 nodes, 1 s, 155 MB at 100; 4448 nodes, 5 s, 1 GB at
#: 400; 10880 nodes, 27 s, 5.5 GB at 1000. A scene comes from untrusted users, so it is
#: held to the figure a shared machine can afford.
MAX_SCENE_LAM = 100.0
#: Largest a/H of ``core.solver.solve_dimensionless``: a trusted caller may spend the
#: 5.5 GB of a/H = 1000 (beyond it the operator no longer fits in memory).
MAX_SOLVER_LAM = 1e3

# ----------------------------------------------------------------------------- times

#: Most output times of a scene (``times.count`` or the length of the ``times`` list).
MAX_SCENE_TIMES = 2_000
#: [day] per year (the Julian year: 50 years of loading are 18262.5 days), for limits
#: and times written in years.
DAYS_PER_YEAR = 365.25

#: Latest output time [day after loading], about 274 years: past any service life a creep
#: law is fitted for (the presets reach 50 years), and a time typed a thousand times too
#: large ("1e9 days") is refused as the slip it is rather than answered.
MAX_SCENE_DAYS = 100_000.0
#: Oldest base at loading [day] (``base.age_at_loading``), as old as the latest output time
#: is late: ages and times after loading add up in the time steps, where an age of 1e14
#: days moved the settlement by 1e-6 (relative) and 1e16 days made a step's matrix singular
#: (the steps of 50 days lost in the age's round-off).
MAX_SCENE_AGE = MAX_SCENE_DAYS
#: Most load durations of one ``core.creep_coefficient_curve`` call (a plotted curve
#: needs a few hundred; each costs a few array operations).
MAX_CURVE_POINTS = 100_000
#: Least span from loading (t = 1) to the last output time on a creeping base, unless
#: every output is at loading: the time stepper's first steps are fractions of the span,
#: and spans of 1e-7 made them fall below the doubles' spacing at t ~ 1 (a singular
#: matrix of its dense output). 5e-7 of the age at loading is about a second.
MIN_CREEP_SPAN = 5e-7
#: Most output times of ``core.solver.solve_dimensionless``: every output time is a
#: column of each mode's history (256 modes x 3 arrays x 10000 times: 60 MB).
MAX_SOLVER_TIMES = 10_000
#: Most points of the general-kernel time grid (a formula creep kernel): the kernel
#: matrix is dense, points^2 doubles (4097: 134 MB), and the stepping costs
#: points^2 x modes. Every output time is a grid point, so this also bounds the output
#: times of such a scene; a grid that would exceed it is never built.
MAX_KERNEL_GRID_POINTS = 4_097
#: Values of the kernel matrix evaluated together, in blocks of rows, so a formula's
#: temporaries stay within :data:`MAX_FORMULA_ELEMENTS` whatever the grid: a formula
#: within the depth and part limits holds at most ~45 live arrays (two per nesting
#: level), below the 64 this block allows for.
KERNEL_BLOCK_ELEMENTS = MAX_FORMULA_ELEMENTS // 64
#: Most steps (accepted and rejected) of the degenerate-kernel time stepper per solve.
#: A load that varies faster than this many steps can follow is refused up front
#: (``core.scene.load_rates``).
MAX_TIME_STEPS = 20_000

# ----------------------------------------------------------------------------- results

#: Most pressure values one call of ``SceneSolution.pressure`` may compute (points x
#: output times): 4e6 doubles are 32 MB (the plotting grid: 201 x 2000 = 4e5).
MAX_PRESSURE_VALUES = 4_000_000

# ----------------------------------------------------------------------------- work

#: Most CPU time one solve may take [s], whatever calls it (the API, the command line, a
#: study's point, the explorer): where the cost cannot be predicted before the work (lift-
#: off under creep follows its zones step by step) the solve checks it as it goes
#: (``core.work``) and stops with a ``ValueError`` naming the field that made it costly.
#: The slowest of 10,000 generated valid scenes took 0.7 s, the presets with 2000 output
#: times at most 11 s; a creep lift-off driven by a sine tilt ran 600 s without it.
MAX_SOLVE_CPU_SECONDS = 60.0
#: The memory a run of the command line may take [bytes], as its address space (plus
#: ``core.work.PER_CORE_BYTES`` per core; ``--max-memory`` changes it): a report with
#: HoloViews, Bokeh and Matplotlib loaded maps 1.6 GiB (0.23 GiB resident), the costliest
#: solve met (a punch touching at 200 crests under creep, stopped at its CPU bound) 1.7 GiB
#: resident. The Python API leaves its caller's process unbounded: there the input limits
#: and the CPU bound hold.
MAX_RUN_MEMORY_BYTES = 4 * 2**30

# ----------------------------------------------------------------------------- back-analysis

#: Most readings of one back-analysis (``core.calibrate``): every reading time is an
#: output time of each solve of the fit, so a scene's output times bound it.
MAX_READINGS = MAX_SCENE_TIMES
#: Largest readings file (CSV or JSON) [bytes]: 2000 rows of five numbers are ~100 kB.
MAX_READINGS_BYTES = 1_000_000
#: Most scene fields fitted at once: every iteration of the fit solves the scene once per
#: fitted field (the finite-difference Jacobian), and a record of settlements and tilts
#: rarely determines more than a few; a study varies at most as many.
MAX_FIT_PARAMETERS = 8
#: Most solves of one fit (its iterations times the fitted fields plus one, and the
#: Jacobian at the answer). Each solve is bounded by :data:`MAX_SOLVE_CPU_SECONDS`; a fit
#: of three fields to 30 readings of the shipped young-concrete scene takes ~20 solves.
MAX_FIT_SOLVES = 400
