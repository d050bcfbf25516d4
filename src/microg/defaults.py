"""The defaults of every command and library entry point, once, and the named presets.

Every ``microg`` command and every library function whose default is one of these names
reads it from here, so the same push gives the same answer in ``analyze``, ``locate`` and
``optimize`` unless the user asks otherwise.  Values are SI (m, kg, s, N).

:data:`PRESETS` holds named groups of settings; ``report`` is the seed report's own
analysis (the assumed-modes planar model in the X-Z plane, one admissible function per
beam, no structural damping: Sections 2-3 of the report), which ``microg reproduce`` uses
and ``--preset report`` selects in ``analyze``, ``locate``, ``optimize`` and ``modes``.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

__all__ = [
    "METHOD",
    "PLANE",
    "DAMPING",
    "ELEMENTS",
    "FUNCTIONS",
    "N_MODES",
    "MAX_FREQ_HZ",
    "DURATION_S",
    "DT_S",
    "REQUIREMENT",
    "FORCE",
    "DIRECTION",
    "CREW_F0_N",
    "CREW_T1_S",
    "CREW_T13_S",
    "CREW_T14_S",
    "LAYOUT_METHOD",
    "NASTRAN_COUPLED_MASS",
    "PRESETS",
    "preset",
]

#: discretisation: 3-D frame finite elements ("fem") or assumed modes ("ritz")
METHOD = "fem"
#: "3d", or the report's planar assumed-modes model "xz"/"yz"
PLANE = "3d"
#: modal damping ratio of the elastic modes (a lightly damped truss structure)
DAMPING = 0.005
#: elements per beam of the frame model (more where masses and joints cut a beam)
ELEMENTS = 10
#: admissible functions per beam and deformation kind of the assumed-modes model (the report's)
FUNCTIONS = 1
#: modes solved for a sparse model (a dense model solves all of them)
N_MODES = 60
#: elastic modes up to this frequency enter a transient response, Hz
MAX_FREQ_HZ = 10.0
#: length of a response record, s
DURATION_S = 200.0
#: output sample interval of a response record, s
DT_S = 0.01
#: the band requirement judged: the ISS vibratory requirement as NASA PIMS codes it
REQUIREMENT = "iss"
#: the disturbance: the report's crew push-off and landing (Eq. 2.16)
FORCE = "crew-pushoff"
#: direction of the disturbance
DIRECTION = "x"
#: the report's push-off: peak 25 lbf (1 lbf = 4.4482216152605 N exactly), N
CREW_F0_N = 25.0 * 0.45359237 * 9.80665
#: end of the push-off ramp, s (Eq. 2.16)
CREW_T1_S = 1.0
#: start of the landing, s (Eq. 2.16)
CREW_T13_S = 13.0
#: end of the landing, s (Eq. 2.16)
CREW_T14_S = 14.0
#: NASTRAN's coupled CBAR mass (a deck with PARAM,COUPMASS > 0) as current NASTRAN forms it:
#: "coupled" (Simcenter Nastran 2020.2); "coupled-nx9" is NX Nastran 9.1's (2014)
NASTRAN_COUPLED_MASS = "coupled"
#: the layout optimiser's discretisation: each trial layout's assumed-modes model is
#: re-assembled incrementally (a frame model would be re-meshed and re-solved, seconds each)
LAYOUT_METHOD = "ritz"

#: named settings: option name (without dashes, as in the commands) -> value
PRESETS: MappingProxyType[str, MappingProxyType[str, Any]] = MappingProxyType(
    {
        "report": MappingProxyType(
            {"method": "ritz", "plane": "xz", "damping": 0.0, "functions": FUNCTIONS}
        ),
    }
)


def preset(name: str) -> dict[str, Any]:
    """The settings of preset ``name`` (a copy), keyed by option name.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS` (``"report"``).

    Raises
    ------
    microg.errors.InputError
        Naming ``preset`` when the name is unknown.
    """
    from microg.errors import InputError

    if name not in PRESETS:
        raise InputError(
            f"unknown preset {name!r}", where="preset", fix=f"use {', '.join(PRESETS)}"
        )
    return dict(PRESETS[name])
