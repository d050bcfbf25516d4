"""Isolation of an experiment package: spring mount with a damped vibration absorber (Section 4).

Modules: :mod:`~microg.isolation.transmissibility` (kernels of Eqs. 4.3-4.7),
:mod:`~microg.isolation.absorber` (Den Hartog / H2 / numerical tuning),
:mod:`~microg.isolation.design` (physical-unit mount design, Section 4.2 claims),
:mod:`~microg.isolation.timedomain` (exact response to a sampled mount acceleration),
:mod:`~microg.plotting.isolation` (Figure 8).
"""

from microg.isolation.absorber import (
    AbsorberTuning,
    den_hartog,
    den_hartog_peak_bound,
    h2_closed_form,
    h2_integral,
    peak_over_band,
    tune_absorber,
)
from microg.isolation.design import (
    ClaimCheck,
    MountDesign,
    Section42Claims,
    check_section42_claims,
    design_mount,
    max_stiffness_no_absorber,
)
from microg.isolation.timedomain import IsolationTimeResponse, IsolatorModel, package_response
from microg.isolation.transmissibility import (
    absorber_tuning_ratio,
    accel_magnification,
    accel_magnification_grid,
    accel_magnification_no_absorber,
    spring_ratio_from_tuning,
    transmissibility,
    transmissibility_no_absorber,
)

__all__ = [
    "AbsorberTuning",
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
