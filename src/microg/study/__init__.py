"""Studies at scale: sweeps over forces, points, directions, damping, isolators and variants.

A study file (TOML, ``docs/scale.md``) names the axes; :func:`sweep` computes every case by
linearity (one modal solve per model variant, every case a row of one matrix product),
serially or on a Dask cluster, and writes one labelled ``xarray.Dataset`` to zarr as it goes.

>>> import microg.study as ms                                  # doctest: +SKIP
>>> result = ms.sweep("examples/study.toml", "out")            # doctest: +SKIP
>>> result.dataset.margin.min("observe")                       # doctest: +SKIP
"""

from __future__ import annotations

from microg.study.plan import CASE_DIMS, Study, load_study, loads_study
from microg.study.run import SweepIncompleteError, SweepResult, sweep
from microg.study.summary import Summary, summarize

__all__ = [
    "CASE_DIMS",
    "Study",
    "Summary",
    "SweepIncompleteError",
    "SweepResult",
    "load_study",
    "loads_study",
    "summarize",
    "sweep",
]
