"""Isolation of an experiment package: spring mount with a damped vibration absorber (Section 4).

Modules: :mod:`~microg.isolation.transmissibility` (kernels of Eqs. 4.3-4.7),
:mod:`~microg.isolation.absorber` (Den Hartog / H2 / numerical tuning),
:mod:`~microg.isolation.design` (physical-unit mount design, Section 4.2 claims),
:mod:`~microg.isolation.timedomain` (exact response to a sampled mount acceleration),
:mod:`~microg.isolation.active` (active isolation: platform, controllers, verification),
:mod:`~microg.plotting.isolation` (Figure 8).
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> module (imported on first use: the absorber optimiser pulls in
#: scipy.optimize and scipy.integrate, which the main job does not always need)
_LAZY: dict[str, str] = {
    "AbsorberTuning": "microg.isolation.absorber",
    "ActiveIsolation": "microg.isolation.active.result",
    "ActivePlant": "microg.isolation.active.plant",
    "design_active": "microg.isolation.active.design",
    "ClaimCheck": "microg.isolation.design",
    "IsolationTimeResponse": "microg.isolation.timedomain",
    "IsolatorModel": "microg.isolation.timedomain",
    "MountDesign": "microg.isolation.design",
    "Section42Claims": "microg.isolation.design",
    "absorber_tuning_ratio": "microg.isolation.transmissibility",
    "accel_magnification": "microg.isolation.transmissibility",
    "accel_magnification_grid": "microg.isolation.transmissibility",
    "accel_magnification_no_absorber": "microg.isolation.transmissibility",
    "check_section42_claims": "microg.isolation.design",
    "den_hartog": "microg.isolation.absorber",
    "den_hartog_peak_bound": "microg.isolation.absorber",
    "design_mount": "microg.isolation.design",
    "h2_closed_form": "microg.isolation.absorber",
    "h2_integral": "microg.isolation.absorber",
    "max_stiffness_no_absorber": "microg.isolation.design",
    "package_response": "microg.isolation.timedomain",
    "peak_over_band": "microg.isolation.absorber",
    "spring_ratio_from_tuning": "microg.isolation.transmissibility",
    "transmissibility": "microg.isolation.transmissibility",
    "transmissibility_no_absorber": "microg.isolation.transmissibility",
    "tune_absorber": "microg.isolation.absorber",
}

__all__ = [
    "AbsorberTuning",
    "ActiveIsolation",
    "ActivePlant",
    "ClaimCheck",
    "IsolationTimeResponse",
    "IsolatorModel",
    "MountDesign",
    "Section42Claims",
    "absorber_tuning_ratio",
    "accel_magnification",
    "accel_magnification_grid",
    "accel_magnification_no_absorber",
    "check_section42_claims",
    "den_hartog",
    "den_hartog_peak_bound",
    "design_active",
    "design_mount",
    "h2_closed_form",
    "h2_integral",
    "max_stiffness_no_absorber",
    "package_response",
    "peak_over_band",
    "spring_ratio_from_tuning",
    "transmissibility",
    "transmissibility_no_absorber",
    "tune_absorber",
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'microg.isolation' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
