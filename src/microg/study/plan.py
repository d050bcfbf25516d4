"""The study file (TOML) and the case plan of a sweep.

A study is the product of its axes (``docs/scale.md``)::

    [study]
    model = "ioc"                       # or a list: paths, shipped names, or tables
    [axes]
    force = ["foot-pushoff-max", "hand-pushoff-mean"]
    at = ["crew", "vertical-lab"]
    direction = ["x", "y", "z"]
    observe = ["lab", "keel-tip"]
    damping = [0.002, 0.005, 0.01]
    isolator = [{ name = "none" }, { name = "soft", k1 = "50 N/m", zeta1 = 0.1 }]
    variant = [{ name = "base" }, { name = "dock-aft", move = "main/Orbiter", to = [...] }]
    [record]                            # defaults: microg.analysis.DEFAULTS
    duration = "200 s"

The full product is the default; ``[[case]]`` tables list sub-products instead (each fixes
some axes to one value or a list; the axes it leaves out take all their values).  Extra named
points (``[[point]]``, as in a station file) are added to every station model.

Reading happens here, validation once: the file's structure (:mod:`microg.study.schema`,
pydantic), then every force (parsed), every point (present in each model it is used on),
every variant (the mass exists, the position is on its carrier), the record
(:mod:`microg.study.expand`).  Every error is one line naming the file and the field
(``study.toml: axes.force[2]: ...``).  The plan (:mod:`microg.study.cases`) holds SI values
only; its names are importable from here.

The case grid has one dimension per axis (:data:`CASE_DIMS`); it is cut into blocks
(:class:`Block`): one model, variant, isolator, damping value and force, a run of application
points, every direction and a run of observed points.  A block is the unit of work, of
storage (one zarr chunk per variable) and of resumption.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import ValidationError

from microg import _args
from microg._io import loads_toml
from microg.errors import InputError
from microg.models.messages import structure_error
from microg.study.cases import (
    BLOCK_CELLS,
    CASE_DIMS,
    Block,
    DirectionItem,
    Discretisation,
    ForceItem,
    IsolatorItem,
    ModelItem,
    Record,
    Study,
    VariantItem,
    default_n_modes,
)
from microg.study.expand import MAX_CASES, MAX_SAMPLES, build_study
from microg.study.schema import MAX_AXIS_VALUES, AxesIn, StudyFileIn

__all__ = [
    "CASE_DIMS",
    "MAX_CASES",
    "MAX_AXIS_VALUES",
    "MAX_STUDY_BYTES",
    "BLOCK_CELLS",
    "ModelItem",
    "VariantItem",
    "IsolatorItem",
    "ForceItem",
    "DirectionItem",
    "Record",
    "Discretisation",
    "Block",
    "Study",
    "load_study",
    "loads_study",
    "default_n_modes",
    "MAX_SAMPLES",
]


#: largest study file, bytes
MAX_STUDY_BYTES = 4 * 2**20


def load_study(path: str | Path) -> Study:
    """Read and validate a study file (see the module docstring and ``docs/scale.md``).

    Parameters
    ----------
    path : str or Path
        The TOML study file; relative paths inside it are relative to its folder.

    Returns
    -------
    Study

    Raises
    ------
    InputError
        One line naming the file and the field.
    """
    p = _args.path(path, "path")
    label = str(path)
    try:
        with p.open("rb") as fh:
            data = fh.read(MAX_STUDY_BYTES + 1)
    except OSError as exc:
        raise InputError(
            f"cannot read the study file: {exc.strerror or exc}",
            where=label,
            fix="give the path of a TOML study file",
        ) from None
    if len(data) > MAX_STUDY_BYTES:
        raise InputError(f"larger than {MAX_STUDY_BYTES // 2**20} MB", where=label)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start})", where=label) from None
    return loads_study(text, filename=label, base_dir=p.resolve().parent)


def loads_study(text: str, *, filename: str = "<study>", base_dir: str | Path = ".") -> Study:
    """Validate the text of a study file.

    Parameters
    ----------
    text : the TOML text
    filename : the file's name in messages
    base_dir : folder against which relative paths (models, force files) are resolved

    Returns
    -------
    Study
    """
    raw = loads_toml(text, filename)
    if isinstance(raw.get("axes"), dict):
        known = set(AxesIn.model_fields)
        for key in raw["axes"]:
            if key not in known:
                raise InputError(
                    f"unknown axis {key!r}",
                    where=f"{filename}: axes.{key}",
                    fix=f"the axes are {', '.join(AxesIn.model_fields)}",
                )
    try:
        doc = StudyFileIn.model_validate(raw)
    except ValidationError as exc:
        err = structure_error(exc, filename, StudyFileIn)
        raise InputError(err.what, where=err.where, fix=err.fix) from None
    return build_study(doc, filename, Path(base_dir), text)
