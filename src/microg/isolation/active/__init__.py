"""Active isolation of a payload: plant, controllers, verification and the one entry point.

Modules: :mod:`~microg.isolation.active.plant` (rigid platform on umbilicals, sensors,
actuators, the generalized plant), :mod:`~microg.isolation.active.target` (g-LIMIT, ARIS and
per-band targets), :mod:`~microg.isolation.active.controller` (acceleration feedback with
centring designed to a target; H2), :mod:`~microg.isolation.active.verify` (stability, margins,
transmissibility, noise floor, time response), :mod:`~microg.isolation.active.presets`
(``aris``, ``g-limit``), :mod:`~microg.isolation.active.result` (:class:`ActiveIsolation`) and
:mod:`~microg.isolation.active.design` (:func:`design_active`).  python-control is imported on
first use.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY: dict[str, str] = {
    "ActiveIsolation": "microg.isolation.active.result",
    "ActivePlant": "microg.isolation.active.plant",
    "Controller": "microg.isolation.active.controller",
    "Target": "microg.isolation.active.target",
    "TimeCheck": "microg.isolation.active.result",
    "design_active": "microg.isolation.active.design",
    "load_preset": "microg.isolation.active.presets",
    "PRESETS": "microg.isolation.active.presets",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'microg.isolation.active' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
