"""The one entry from a model to a :class:`~microg.structure.Structure`.

Every path of microg (the main job, ``modes``, ``locate``, the layout optimiser, sweeps)
discretises through :func:`discretize`, so one model gives one structure whatever the
command.  Defaults live here, once:

* ``method="fem"``: 3-D frame finite elements, :data:`DEFAULT_ELEMENTS` per beam;
* ``method="ritz"``: assumed modes, ``plane="3d"`` (bending both ways, torsion, axial) or
  the report's planar ``"xz"``/``"yz"`` model, :data:`DEFAULT_FUNCTIONS` function per beam;
* ``gravity_gradient=False``: the free-free structure (rigid-body modes exactly zero).
  With True the libration stiffness of Eqs. 2.27-2.28 / App. B-2 restrains the rotations.
"""

from __future__ import annotations

from typing import Any

from microg import _args, defaults
from microg.errors import InputError
from microg.structure.structure import Structure

__all__ = [
    "DEFAULT_ELEMENTS",
    "DEFAULT_FUNCTIONS",
    "METHODS",
    "PLANES",
    "discretize",
]

#: frame elements per beam (more where masses, points and joints cut a beam)
DEFAULT_ELEMENTS = defaults.ELEMENTS
#: assumed functions per beam and deformation kind (1 is the report's model)
DEFAULT_FUNCTIONS = defaults.FUNCTIONS
METHODS = ("fem", "ritz")
PLANES = ("3d", "xz", "yz")


def discretize(
    model: Any,
    method: str = defaults.METHOD,
    *,
    plane: str = defaults.PLANE,
    n: int | None = None,
    gravity_gradient: bool = False,
    constrained: bool = False,
) -> Structure:
    """Discretise a station model (or pass a modal model's structure through).

    Parameters
    ----------
    model : Station, GraphModel or ModalModel
        The model, SI.  A general frame (graph) model is assembled by
        :func:`microg.structure.frame.build_frame`; an imported modal model becomes a
        structure in modal coordinates (:func:`microg.structure.modal.modal_structure`);
        ``method``, ``plane`` and ``n`` apply to tree station models only.
    method : {"fem", "ritz"}
        3-D frame finite elements, or assumed modes (Rayleigh-Ritz).
    plane : {"3d", "xz", "yz"}
        ``ritz`` only: the 3-D model or the report's planar model in that plane.
    n : int, optional
        Elements per beam (``fem``, default :data:`DEFAULT_ELEMENTS`) or functions per beam
        (``ritz``, default :data:`DEFAULT_FUNCTIONS`).
    gravity_gradient : bool
        Add the gravity-gradient (libration) stiffness on the rigid rotations.
    constrained : bool
        A frame (graph) model only: apply its single-point constraints (a NASTRAN deck's SPC
        set), as the clamped run does; default free-free.

    Returns
    -------
    Structure
    """
    kind = type(model).__name__
    if kind not in ("ModalModel", "GraphModel", "Station") and not isinstance(model, Structure):
        raise InputError(
            f"must be a Station, a frame (graph) model, a modal model or a Structure, got {kind}",
            where="model",
            fix="load a file with microg.load_model(path)",
        )
    _args.boolean(gravity_gradient, "gravity_gradient")
    _args.boolean(constrained, "constrained")
    if n is not None:
        n = _args.integer(n, "n", lo=1)
    if kind == "ModalModel":
        from microg.structure.modal import modal_structure

        return modal_structure(model)
    if kind == "GraphModel":
        from microg.structure.frame import build_frame

        return build_frame(model, constrained=constrained)
    if constrained:
        raise InputError(
            "applies to frame (graph) models only, such as a NASTRAN deck",
            where="constrained",
            fix="omit it: station models are free-free",
        )
    if isinstance(model, Structure):
        return model
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}", where="method", fix="use fem or ritz")
    if plane not in PLANES:
        raise InputError(f"unknown plane {plane!r}", where="plane", fix="use 3d, xz or yz")
    if method == "fem":
        if plane != "3d":
            raise InputError(
                "applies to method ritz only (frame elements are always 3-D)",
                where="plane",
                fix="omit it, or use method ritz",
            )
        from microg.structure.fem import build_fem

        return build_fem(
            model, elements_per_beam=n or DEFAULT_ELEMENTS, gravity_gradient=gravity_gradient
        )
    from microg.structure.ritz import build_ritz

    return build_ritz(
        model,
        None if plane == "3d" else plane,
        n or DEFAULT_FUNCTIONS,
        gravity_gradient=gravity_gradient,
    )
