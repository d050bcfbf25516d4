"""Preset active isolators (``aris``, ``g-limit``) from ``data/active_presets.toml``, with sources.

Each preset's parameters carry their origin (a citation, or "ILLUSTRATIVE ASSUMPTION"): see the
data file.  :func:`load_preset` returns the plant and the preset's default target.
"""

from __future__ import annotations

import functools
from importlib import resources
from typing import Any

from microg.errors import InputError
from microg.isolation.active.plant import ActivePlant

__all__ = ["PRESETS", "load_preset", "preset_sources"]

#: the shipped presets
PRESETS = ("aris", "g-limit")

_FIELDS = (
    "mass_kg",
    "inertia_kg_m2",
    "cm_offset_m",
    "umbilical_k_N_per_m",
    "umbilical_c_N_s_per_m",
    "umbilical_k_N_m_per_rad",
    "umbilical_c_N_m_s_per_rad",
    "rattlespace_m",
    "rattlespace_rad",
    "actuator_force_N",
    "actuator_torque_N_m",
    "accel_noise_ug_per_rthz",
    "accel_bandwidth_hz",
    "position_noise_m_per_rthz",
    "position_range_m",
    "sample_rate_hz",
    "delay_s",
    "max_loop_hz",
)


@functools.cache
def _table() -> dict[str, Any]:
    from microg._io import loads_toml

    text = resources.files("microg").joinpath("data/active_presets.toml").read_text("utf-8")
    return loads_toml(text, "active_presets.toml")


def preset_sources(name: str) -> dict[str, str]:
    """Parameter -> where its value comes from, for preset ``name``."""
    return dict(_entry(name).get("sources", {}))


def _entry(name: str) -> dict[str, Any]:
    table = _table()
    if name not in table:
        raise InputError(
            f"unknown preset {name!r}", where="preset", fix=f"use {' or '.join(PRESETS)}"
        )
    return table[name]


def load_preset(name: str, **overrides: Any) -> tuple[ActivePlant, str]:
    """(plant, default target name) of preset ``name``, with ``overrides`` of its fields (SI).

    A field overridden is marked ``"given"`` in the plant's sources.
    """
    entry = _entry(name)
    unknown = sorted(set(overrides) - set(_FIELDS))
    if unknown:
        raise InputError(f"unknown parameter {unknown[0]!r}", where="preset")
    values = {k: entry[k] for k in _FIELDS}
    sources = preset_sources(name)
    for k, v in overrides.items():
        if v is not None:
            values[k] = v
            sources[k] = "given"
    plant = ActivePlant(**values, name=name, sources=sources)
    return plant, str(entry.get("target", "g-limit"))
