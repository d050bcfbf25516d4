"""The structure of a study file (pydantic): every table and key, and the type of each value.

One model per TOML table (``[study]``, ``[axes]``, ``[record]``, ``[[case]]``, ``[[point]]``);
unknown keys are refused, numbers must be finite, quantities are numbers or strings with a
unit (parsed later, :mod:`microg.study.expand`), directions an axis name or three numbers.
Defaults are the analysis' (:data:`microg.analysis.DEFAULTS`); see ``docs/scale.md``.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PlainValidator, StrictBool, StrictStr

from microg.analysis import DEFAULTS
from microg.models.messages import fail
from microg.models.schema import PointIn

__all__ = [
    "MAX_AXIS_VALUES",
    "AxesIn",
    "CaseIn",
    "IsolatorIn",
    "ModelIn",
    "RecordIn",
    "StudyFileIn",
    "StudyIn",
    "VariantIn",
]

#: most values on one axis
MAX_AXIS_VALUES = 100_000


def _quantity(value: Any) -> str | float:
    if isinstance(value, str):
        return value
    if isinstance(value, int | float) and not isinstance(value, bool):
        if not math.isfinite(value):
            raise fail("not_finite", "expected a finite value", "give a finite number", value)
        return float(value)
    raise fail("quantity", "expected a number or a quantity", 'write e.g. "10 m"', value)


def _number(value: Any) -> float:
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return float(value)
    raise fail("number", "expected a finite number", "write a number without quotes", value)


def _direction(value: Any) -> str | list[float]:
    if isinstance(value, str):
        return value
    if isinstance(value, list) and len(value) == 3:
        return [_number(v) for v in value]
    raise fail(
        "direction", "expected an axis or three numbers", 'write "x", "-z" or [1, 0, 0]', value
    )


_Q = Annotated[str | float, PlainValidator(_quantity)]
_Num = Annotated[float, PlainValidator(_number)]
_Dir = Annotated[str | list[float], PlainValidator(_direction)]
_Name = Annotated[StrictStr, Field(min_length=1, max_length=200)]


class _In(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ModelIn(_In):
    """A model as a table: a path or shipped name, with the units and points of modal files."""

    path: _Name
    name: _Name | None = None
    units: StrictStr | None = None
    points: StrictStr | None = None


_ModelRef = _Name | ModelIn


class StudyIn(_In):
    """``[study]``."""

    name: _Name | None = None
    description: Annotated[StrictStr, Field(max_length=2000)] = ""
    model: _ModelRef | Annotated[list[_ModelRef], Field(min_length=1, max_length=1000)]
    method: StrictStr = DEFAULTS["method"]
    plane: StrictStr = DEFAULTS["plane"]
    functions: Annotated[int, Field(ge=1, le=10_000)] | None = None
    elements: Annotated[int, Field(ge=1, le=10_000)] | None = None
    n: Annotated[int, Field(ge=1, le=10_000)] | None = None  # deprecated: functions/elements
    n_modes: Annotated[int, Field(ge=1, le=2000)] | None = None
    gravity_gradient: StrictBool = DEFAULTS["gravity_gradient"]
    units: StrictStr | None = None
    package_mass: _Q | None = None


class IsolatorIn(_In):
    """One mount design of the ``isolator`` axis."""

    name: _Name
    k1: _Q | None = None
    f_n: _Q | None = None
    zeta1: _Num = 0.0
    package_mass: _Q | None = None
    report_rule: StrictBool = False
    band: Annotated[list[_Q], Field(min_length=2, max_length=2)] | None = None
    target: _Num = 1.0
    mu: _Num | None = None


class VariantIn(_In):
    """One model variant: the model as it is, a mass moved, or another model file."""

    name: _Name
    move: _Name | None = None
    to: Annotated[list[_Q], Field(min_length=3, max_length=3)] | None = None
    s: _Q | None = None
    model: _ModelRef | None = None


def _axis(item: Any) -> Any:
    return Annotated[list[item], Field(max_length=MAX_AXIS_VALUES)]


class AxesIn(_In):
    """``[axes]``: the values of each axis (an axis left out takes its default)."""

    force: _axis(_Name) | None = None  # type: ignore[valid-type]
    at: _axis(_Name) | None = None  # type: ignore[valid-type]
    direction: _axis(_Dir) | None = None  # type: ignore[valid-type]
    observe: _axis(_Name) | None = None  # type: ignore[valid-type]
    damping: _axis(_Num) | None = None  # type: ignore[valid-type]
    isolator: _axis(IsolatorIn) | None = None  # type: ignore[valid-type]
    variant: _axis(VariantIn) | None = None  # type: ignore[valid-type]


class RecordIn(_In):
    """``[record]``: the output record and the requirement (defaults: the analysis')."""

    duration: _Q = DEFAULTS["duration_s"]
    dt: _Q = DEFAULTS["dt_s"]
    max_freq: _Q = DEFAULTS["max_freq_hz"]
    requirement: StrictStr = DEFAULTS["requirement"]
    peaks: Literal["verdict", "exact"] = "verdict"


def _one_or_list(item: Any) -> Any:
    return item | Annotated[list[item], Field(min_length=1, max_length=MAX_AXIS_VALUES)]


class CaseIn(_In):
    """``[[case]]``: a sub-product; each key fixes an axis to one value or a list of values."""

    model: _one_or_list(_Name) | None = None  # type: ignore[valid-type]
    variant: _one_or_list(_Name) | None = None  # type: ignore[valid-type]
    isolator: _one_or_list(_Name) | None = None  # type: ignore[valid-type]
    damping: _one_or_list(_Num) | None = None  # type: ignore[valid-type]
    force: _one_or_list(_Name) | None = None  # type: ignore[valid-type]
    at: _one_or_list(_Name) | None = None  # type: ignore[valid-type]
    direction: _Dir | Annotated[list[_Dir], Field(min_length=1)] | None = None
    observe: _one_or_list(_Name) | None = None  # type: ignore[valid-type]


class StudyFileIn(_In):
    """A whole study file."""

    study: StudyIn
    axes: AxesIn = AxesIn()
    record: RecordIn = RecordIn()
    case: Annotated[list[CaseIn], Field(max_length=100_000)] | None = None
    point: Annotated[list[PointIn], Field(max_length=10_000)] = []
