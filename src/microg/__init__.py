"""microg: the microgravity environment of an orbiting space station.

The data flow is one way::

    model -> structure (M, K, point maps) or an imported modal model -> modes
          -> response (time or frequency domain) -> assessment / isolation -> report / CLI

The public API does the main job in a few lines (see ``docs/api.md``)::

    >>> import microg
    >>> station = microg.load_station("ioc")
    >>> modes = microg.solve_modes(station, method="fem")
    >>> int(modes.n_rigid)
    6
    >>> result = microg.analyze(station, force="crew-pushoff", at="crew", observe=["lab"])
    >>> result.observations["lab"].peak_accel_g > 1e-5
    True

Everything is imported lazily: ``import microg`` loads neither scipy, pint nor matplotlib.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from microg import defaults
from microg.errors import InputError, MicrogError, ModelError, SolverError

if TYPE_CHECKING:
    from microg.analysis import Analysis, AnalysisOptions, Disturbance, Observation, analyze
    from microg.dynamics.forces import ForceHistory, crew_pushoff
    from microg.dynamics.modes import Modes
    from microg.models.station import Station
    from microg.structure.discretize import discretize
    from microg.structure.structure import Structure
    from microg.study.plan import load_study
    from microg.study.run import SweepResult, sweep

__version__ = "0.2.0"

#: public name -> "module:attribute", imported on first use
_LAZY: dict[str, str] = {
    "analyze": "microg.analysis:analyze",
    "Analysis": "microg.analysis:Analysis",
    "AnalysisOptions": "microg.analysis:AnalysisOptions",
    "Disturbance": "microg.analysis:Disturbance",
    "Observation": "microg.analysis:Observation",
    "load_station": "microg.models.toml:load_station",
    "Station": "microg.models.station:Station",
    "discretize": "microg.structure.discretize:discretize",
    "Structure": "microg.structure.structure:Structure",
    "Modes": "microg.dynamics.modes:Modes",
    "ForceHistory": "microg.dynamics.forces:ForceHistory",
    "crew_pushoff": "microg.dynamics.forces:crew_pushoff",
    "sweep": "microg.study.run:sweep",
    "SweepResult": "microg.study.run:SweepResult",
    "load_study": "microg.study.plan:load_study",
}

__all__ = [
    "Analysis",
    "AnalysisOptions",
    "Disturbance",
    "ForceHistory",
    "InputError",
    "MicrogError",
    "ModelError",
    "Modes",
    "Observation",
    "SolverError",
    "Station",
    "Structure",
    "SweepResult",
    "__version__",
    "analyze",
    "crew_pushoff",
    "discretize",
    "load_model",
    "load_station",
    "load_study",
    "solve_modes",
    "sweep",
]


def __getattr__(name: str) -> Any:
    target = _LAZY.get(name)
    if target is None:
        raise AttributeError(f"module 'microg' has no attribute {name!r}")
    module, attr = target.split(":")
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


def load_model(path: Any, **options: Any) -> Any:
    """A model from a file or a shipped name: a station (TOML) or an imported modal model.

    Parameters
    ----------
    path : str or Path
        A shipped model name (``"ioc"``), a station ``.toml`` file, or (with the interop
        readers) a NASTRAN ``.op2``/``.op4``/``.bdf``, a UFF ``.unv``, or microg's own modal file.
    **options
        Reader options: ``units`` (``"in, lbf, s"``; NASTRAN files declare none), ``wtmass``,
        ``points`` (a TOML points file naming grids), ``subcase`` (an OP2's subcase).
    """
    from microg.models.load import load_model as _load

    return _load(path, **options)


def solve_modes(
    model: Any,
    method: str = defaults.METHOD,
    *,
    plane: str = defaults.PLANE,
    n: int | None = None,
    n_modes: int | None = None,
    gravity_gradient: bool = False,
) -> Modes:
    """Free-free modes of a model: rigid-body modes exactly zero, mass-normalised shapes.

    Parameters
    ----------
    model : Station, modal model, Structure, str or Path
        A model object, a model path or a shipped name.
    method : {"fem", "ritz"}
        Frame finite elements, or assumed modes.
    plane : {"3d", "xz", "yz"}
        ``ritz``: the 3-D model or the report's planar model.
    n : int, optional
        Elements (fem) or functions (ritz) per beam.
    n_modes : int, optional
        Number of lowest modes (default: all for dense models, a fixed count for sparse ones).
    gravity_gradient : bool
        Restrain the rigid rotations by the gravity-gradient (libration) stiffness.

    Returns
    -------
    Modes
    """
    import os

    from microg import _args
    from microg.dynamics.modes import solve_modes as _solve
    from microg.structure.discretize import discretize
    from microg.structure.structure import Structure

    if isinstance(model, str | os.PathLike):
        model = load_model(model)
    if n_modes is not None:
        n_modes = _args.integer(n_modes, "n_modes", lo=1)
    structure = (
        model
        if isinstance(model, Structure)
        else discretize(model, method, plane=plane, n=n, gravity_gradient=gravity_gradient)
    )
    return _solve(structure, n_modes)
