"""One entry to every model kind: ``load_model(path, units=..., wtmass=..., points=...)``.

Dispatch by suffix:

* ``.op2``: NASTRAN SOL 103 results (:func:`microg.models.nastran.modal_model_from_op2`);
* ``.op4``: NASTRAN a-set matrices (MAA/KAA, or EXTSEOUT's MXX/KXX), their DOFs from the run's
  files beside (:func:`microg.models.dofmap.dof_map_for_op4`: ``<stem>.op2`` USET/EQEXIN,
  ``<stem>.pch`` EXTRN, else ``<stem>.dofmap.csv``: ``grid, component, x, y, z`` per row);
* ``.unv`` / ``.uff``: UFF 15/2411 + 55 (+164) (:func:`microg.models.uff.modal_model_from_uff`);
* ``.npz``: microg's own modal-model file (:func:`microg.models.modal.load_modal_model`);
* ``.toml`` or a shipped name: a station (:func:`microg.models.toml.load_station`);
* ``.bdf`` / ``.dat`` / ``.blk`` / ``.nas`` / ``.bulk``: a NASTRAN deck (or bulk data), solved by
  microg's FE (:func:`microg.models.bdf.load_bdf`).

A ``.pch`` punch file or an ``.f06`` listing is NASTRAN output that is not a model: it is refused,
naming the file to give instead.

NASTRAN files declare no units: ``units`` (``"in, lbf, s"``) is required for them, from the
argument or the points file; a missing declaration is an error, never a guess.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from microg import _args
from microg.errors import InputError

if TYPE_CHECKING:
    from microg.models.modal import ModelOptions

__all__ = ["load_model", "loads_station", "MODEL_SUFFIXES", "DECK_SUFFIXES"]

DECK_SUFFIXES = (".bdf", ".dat", ".blk", ".nas", ".bulk")
# NASTRAN output that is not a model, with what to give instead
_NOT_A_MODEL = {
    ".pch": "a punch file holds a run's output tables, not a model",
    ".f06": "an F06 is NASTRAN's printed listing, not a model",
}
MODEL_SUFFIXES = (".op2", ".op4", ".unv", ".uff", ".npz", ".toml", *DECK_SUFFIXES, *_NOT_A_MODEL)


def _units(
    units: str | None, wtmass: float | None, opts: ModelOptions, path: str, need: bool
) -> Any:
    text = units if units is not None else opts.units
    wt = wtmass if wtmass is not None else opts.wtmass
    if text is None:
        if need:
            raise InputError(
                "NASTRAN files declare no units and none was given",
                where=path,
                fix='state them, e.g. units="in, lbf, s" (or in the points file)',
            )
        return None
    from microg.models.file_units import parse_units

    return parse_units(text, where="units", wtmass=wt)


def loads_station(path: str | Path, points: str | Path | None = None) -> bool:
    """Whether :func:`load_model` reads ``path`` as a station model (TOML, or a shipped name).

    Parameters
    ----------
    path : str or Path
        As for :func:`load_model`.
    points : str or Path, optional
        As for :func:`load_model` (a points file makes ``path`` a modal model's).
    """
    suffix = Path(path).suffix.lower()
    return points is None and (suffix == ".toml" or suffix not in MODEL_SUFFIXES)


def _only_for_foreign_files(units: str | None, wtmass: float | None, kind: str) -> None:
    """Refuse NASTRAN/UFF reader options given for a model that declares its own units."""
    for name, value in (("units", units), ("wtmass", wtmass)):
        if value is not None:
            raise InputError(
                f"applies to NASTRAN and UFF files only: {kind} declares its own units",
                where=name,
                fix="leave it out",
            )


def load_model(
    path: str | Path,
    units: str | None = None,
    wtmass: float | None = None,
    points: str | Path | None = None,
    subcase: int | None = None,
    coupled_mass: str | None = None,
    superelement: int | None = None,
) -> Any:
    """Read a model of any kind microg knows (see the module docstring).

    Parameters
    ----------
    path : str or Path
        Model file, or the name of a shipped station model.
    units : str, optional
        ``"LENGTH, FORCE, TIME"`` of a NASTRAN file (or of a UFF file without dataset 164).
    wtmass : float, optional
        NASTRAN PARAM,WTMASS of the run.
    points : str or Path, optional
        Points/options TOML file (named grids, kinds, and optionally ``units``/``wtmass``).
    subcase : int, optional
        The subcase of an OP2 with modes of several (an OP2 option only).
    coupled_mass : {"coupled", "coupled-nx9", "consistent"}, optional
        The mass of a NASTRAN deck with ``PARAM,COUPMASS`` > 0 (a deck option only;
        :func:`microg.models.bdf.load_bdf`): default NASTRAN's coupled CBAR mass as current
        Simcenter Nastran forms it (:data:`microg.defaults.NASTRAN_COUPLED_MASS`).
    superelement : int, optional
        The superelement of an OP4 holding the matrices of several (nas2cam's SE_START
        blocks) or beside an OP2 holding the DOFs of several (an OP4 option only).

    Returns
    -------
    ModalModel or Station
    """
    p = _args.path(path, "path")
    suffix = p.suffix.lower()
    label = str(path)
    if subcase is not None and suffix != ".op2":
        raise InputError("applies to OP2 files only", where="subcase", fix="leave it out")
    if suffix in _NOT_A_MODEL:
        raise InputError(
            _NOT_A_MODEL[suffix],
            where=label,
            fix="give the run's .op2 (SOL 103 modes), its .op4 (MAA/KAA) or its deck (.bdf, .dat)",
        )
    if coupled_mass is not None and suffix not in DECK_SUFFIXES:
        raise InputError(
            "applies to NASTRAN decks (.bdf, .dat, .blk, .nas, .bulk) only",
            where="coupled_mass",
            fix="leave it out",
        )
    if subcase is not None and (
        isinstance(subcase, bool) or not isinstance(subcase, int) or subcase < 1
    ):
        raise InputError(f"expected a positive integer, got {subcase!r}", where="subcase")
    if superelement is not None and suffix != ".op4":
        raise InputError("applies to OP4 files only", where="superelement", fix="leave it out")
    if superelement is not None and (
        isinstance(superelement, bool) or not isinstance(superelement, int) or superelement < 0
    ):
        raise InputError(
            f"expected a superelement id (0 or more), got {superelement!r}", where="superelement"
        )
    if loads_station(path, points):
        # a station (a file or a shipped name): the modal readers are not needed
        from microg.models.toml import load_station

        _only_for_foreign_files(units, wtmass, "a station or graph model")
        return load_station(p if suffix == ".toml" else path)
    from microg.models.modal import ModelOptions, load_modal_model, read_options

    opts = read_options(points) if points is not None else ModelOptions()
    if suffix not in MODEL_SUFFIXES:
        from microg.models.toml import load_station

        if opts.points:
            raise InputError("a points file applies to modal models only", where=str(points))
        _only_for_foreign_files(units, wtmass, "a station or graph model")
        return load_station(path)
    if suffix == ".toml":
        from microg.models.toml import load_station

        _only_for_foreign_files(units, wtmass, "a station or graph model")
        return load_station(p)
    if suffix in DECK_SUFFIXES:
        from microg.models.bdf import load_bdf

        u = _units(units, wtmass, opts, label, need=True)
        return load_bdf(p, units=u, points=opts.points, coupled_mass=coupled_mass)
    if not p.is_file():
        raise InputError("no such file", where=label)
    if suffix == ".npz":
        _only_for_foreign_files(units, wtmass, "microg's own modal file")
        return load_modal_model(p, points=opts.points)
    if suffix in (".unv", ".uff"):
        from microg.models.uff import modal_model_from_uff

        u = _units(units, wtmass, opts, label, need=False)
        return modal_model_from_uff(p, units=u, points=opts.points)
    if suffix == ".op2":
        from microg.models.nastran import modal_model_from_op2

        u = _units(units, wtmass, opts, label, need=True)
        return modal_model_from_op2(p, u, points=opts.points, subcase=subcase)
    from microg.models.nastran import modal_model_from_op4

    u = _units(units, wtmass, opts, label, need=True)
    return modal_model_from_op4(p, u, points=opts.points, superelement=superelement)
