"""The main job: a station's microgravity environment under crew disturbances.

:func:`analyze` is the public entry (``microg.analyze``); ``microg analyze`` on the command
line parses its options and calls it.  It loads or takes a model, discretises it through
:func:`microg.structure.discretize.discretize`, solves the free-free modes, applies the
disturbances (exact piecewise-linear modal response, damped modes, rigid-body modes
included), assesses the acceleration at the observed points against a requirement, and
advises isolation where a point does not comply.  It returns one :class:`Analysis`; the
CLI and the HTML report only read it.

Every default lives in one place (:data:`DEFAULTS`).  Inputs that would make a verdict
meaningless are refused (:class:`~microg.errors.InputError` naming the parameter); inputs
that make it shaky put a line in :attr:`Analysis.warnings`.

The modules: :mod:`~microg.analysis.options` (defaults, disturbances, options),
:mod:`~microg.analysis.inputs` (a user's arguments to SI values), :mod:`~microg.analysis.job`
(the orchestration), :mod:`~microg.analysis.transient` (the transient regime),
:mod:`~microg.analysis.contributions` (what each mode contributes),
:mod:`~microg.analysis.result` (the results), :mod:`~microg.analysis.provenance` (the run's
record).
"""

from __future__ import annotations

from microg.analysis.contributions import ModeContributions
from microg.analysis.job import analyze, run_analysis
from microg.analysis.options import (
    DEFAULT_SOURCE_MODES,
    DEFAULTS,
    MAX_SAMPLES,
    REPORT_LIMIT_G,
    REQUIREMENT_INTERVAL_S,
    AnalysisOptions,
    Disturbance,
)
from microg.analysis.result import Analysis, Observation

__all__ = [
    "DEFAULTS",
    "DEFAULT_SOURCE_MODES",
    "MAX_SAMPLES",
    "REPORT_LIMIT_G",
    "REQUIREMENT_INTERVAL_S",
    "Disturbance",
    "AnalysisOptions",
    "ModeContributions",
    "Observation",
    "Analysis",
    "analyze",
    "run_analysis",
]
