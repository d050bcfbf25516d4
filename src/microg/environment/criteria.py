"""One verdict per criterion of an assessment: judged, reported only, or undecided.

Each criterion an :class:`~microg.environment.assessment.Assessment` looks at gets one
:class:`CriterionVerdict`:

* ``judged``: the criterion enters ``complies``; ``complies`` and ``margin`` (limit / value,
  >= 1 passes) say how it came out.  The requirement's resolved bands (the worst band's
  margin), its peak limit when it has one, and every *verified* transient criterion.
* ``reported``: the value is shown against a limit that does not enter ``complies`` (an
  unverified transient criterion, or a figure quoted for comparison), with the limit's source.
* ``undecided``: the record cannot decide the criterion (no band resolved; unresolved bands
  whose estimates exceed their limits), with why and what would decide it.  An undecided
  criterion makes ``complies`` false: compliance is not shown.

``complies`` of the assessment is exactly: every judged criterion complies and none is
undecided (:func:`verdict_complies`).  The verdict said to the user is three-way
(:func:`overall_verdict`): ``fails`` when a judged criterion fails (whatever the undecided
ones would say), ``undecided`` when none fails but one is undecided (compliance is not shown,
and neither is a failure), ``complies`` otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from microg._json import json_number
from microg.environment.bands import MIN_BINS, MIN_TIME_BANDWIDTH
from microg.units import G0

__all__ = [
    "HEADLINE",
    "STATUSES",
    "VERDICTS",
    "CriterionVerdict",
    "combine_verdicts",
    "criterion_verdicts",
    "overall_verdict",
    "verdict_complies",
]

#: the kinds of criterion verdict
STATUSES = ("judged", "reported", "undecided")

#: the verdicts of an assessment (:func:`overall_verdict`)
VERDICTS = ("complies", "fails", "undecided")

#: each verdict as the console's headline says it
HEADLINE = {"complies": "complies", "fails": "DOES NOT COMPLY", "undecided": "UNDECIDED"}


@dataclass(frozen=True)
class CriterionVerdict:
    """The verdict on one criterion.

    Attributes
    ----------
    name : the criterion, e.g. ``"iss bands"``, ``"peak-1000ug-per-axis"``
    status : one of :data:`STATUSES`
    complies : judged or reported: value within the limit; None when undecided
    margin : limit / value (>= 1 passes; inf for a zero value; NaN when undecided)
    value, limit : the judged quantity and its limit, in ``unit``
    unit : ``"g"`` or ``"micro-g s"``
    source : citation of the limit
    why : for ``undecided`` why and what would decide it; for ``reported`` why it does not
        enter the verdict; for ``judged`` what was judged (e.g. the worst band)
    """

    name: str
    status: str
    complies: bool | None
    margin: float
    value: float
    limit: float
    unit: str
    source: str
    why: str

    def line(self) -> str:
        """The console line: ``name: complies (margin 1.5) ...``."""
        if self.status == "undecided":
            return f"{self.name}: undecided: {self.why}"
        word = "complies" if self.complies else "FAILS"
        head = "" if self.status == "judged" else "reported only: "
        line = (
            f"{self.name}: {head}{word} (margin {self.margin:.3g}; {self.value:.3g} "
            f"{self.unit} against {self.limit:.3g} {self.unit}); {self.why}"
        )
        return line if self.status == "judged" else f"{line} (limit from {self.source})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready criterion; keys carry the unit.

        ``value_g``/``limit_g`` (peaks, band RMS) or ``value_ug_s``/``limit_ug_s`` (integrated
        accelerations); an infinite margin is ``"inf"``, an undecided one None.
        """
        suffix = _JSON_SUFFIX[self.unit]
        return {
            "name": self.name,
            "status": self.status,
            "complies": self.complies,
            "margin": json_number(self.margin),
            f"value{suffix}": json_number(self.value),
            f"limit{suffix}": json_number(self.limit),
            "source": self.source,
            "why": self.why,
        }


#: the JSON key suffix of each unit a criterion's value is in
_JSON_SUFFIX = {"g": "_g", "micro-g s": "_ug_s"}


def _margin(limit: float, value: float) -> float:
    return float("inf") if value <= 0 else float(limit / value)


def criterion_verdicts(
    a: Any, extra: tuple[CriterionVerdict, ...] = ()
) -> tuple[CriterionVerdict, ...]:
    """Every criterion of an assessment, one verdict each (see the module docstring).

    Parameters
    ----------
    a : the :class:`~microg.environment.assessment.Assessment` (not imported here: the
        assessment imports this module)
    extra : further reported-only criteria to list after the assessment's own
    """
    to = a.third_octave
    out: list[CriterionVerdict] = []
    nan = float("nan")
    bands = f"{a.requirement} bands"
    wb = a.worst_band
    if wb is not None:
        judged = to.judged
        ok = bool(np.all(to.rms_g[:, judged] <= to.limit_g[judged]))
        lo, hi = to.verdict_range_hz or (nan, nan)
        out.append(
            CriterionVerdict(
                bands,
                "judged",
                ok,
                wb.margin,
                wb.rms_g,
                wb.limit_g,
                "g",
                a.requirement_source,
                f"worst of the {int(judged.sum())} resolved bands ({lo:.3g}-{hi:.3g} Hz): "
                f"{wb.center_hz:.3g} Hz, axis {wb.axis}",
            )
        )
    else:
        out.append(
            CriterionVerdict(
                bands, "undecided", None, nan, nan, nan, "g", a.requirement_source,
                f"the {a.record_s:.4g}-s record resolves no band; lengthen the record",
            )
        )  # fmt: skip
    over = ~to.judged & np.any(to.rms_g > to.limit_g, axis=0)
    if np.any(over):
        idx = np.nonzero(over)[0]
        short = [int(i) for i in idx if not _needs_faster_sampling(to.reasons, int(i))]
        fix = []
        if short:
            need = max(_record_needed(a, i) for i in short)
            fix.append(f"a record (or Welch segment) of >= {need:.4g} s")
        if len(short) < idx.size:
            fix.append("a shorter sample interval (the bands reach the Nyquist or cutoff)")
        centres = ", ".join(f"{to.center_hz[i]:.3g}" for i in idx)
        worst = int(idx[np.argmax(to.rms_g[:, idx].max(axis=0) / to.limit_g[idx])])
        out.append(
            CriterionVerdict(
                f"{a.requirement} unresolved bands",
                "undecided",
                None,
                nan,
                float(to.rms_g[:, worst].max()),
                float(to.limit_g[worst]),
                "g",
                a.requirement_source,
                f"bands {centres} Hz are not resolved by the {a.record_s:.4g}-s record and "
                f"their estimates exceed their limits; {' and '.join(fix)} would judge them",
            )
        )
    if a.peak_limit_g is not None:
        out.append(
            CriterionVerdict(
                f"{a.requirement} peak",
                "judged",
                a.peak_accel_g <= a.peak_limit_g,
                _margin(a.peak_limit_g, a.peak_accel_g),
                a.peak_accel_g,
                a.peak_limit_g,
                "g",
                a.requirement_source,
                "peak magnitude over the record",
            )
        )
    if a.transient is not None:
        for c in a.transient.checks:
            cr = c.criterion
            scale = 1e6 / G0 if cr.is_integral else 1.0 / G0
            unit = "micro-g s" if cr.is_integral else "g"
            out.append(
                CriterionVerdict(
                    cr.name,
                    "judged" if cr.verified else "reported",
                    bool(c.complies),
                    _margin(cr.limit, c.value),
                    c.value * scale,
                    cr.limit * scale,
                    unit,
                    cr.source,
                    f"{a.transient.criteria} transient criterion ({c.basis})"
                    if cr.verified
                    else "its limit is unverified, so it does not enter the verdict",
                )
            )
    return (*out, *extra)


def _needs_faster_sampling(reasons: tuple[str, ...], i: int) -> bool:
    """Band ``i`` is unresolved for its top edge (Nyquist or the data's cutoff)."""
    r = reasons[i] if i < len(reasons) else ""
    return "Nyquist" in r or "cutoff" in r


def _record_needed(a: Any, i: int) -> float:
    """Shortest record that resolves band ``i`` (both rules of microg.environment.bands), s."""
    to = a.third_octave
    width = float(to.upper_hz[i] - to.lower_hz[i])
    return max(MIN_BINS, MIN_TIME_BANDWIDTH) / width


def verdict_complies(verdicts: tuple[CriterionVerdict, ...]) -> bool:
    """Every judged criterion complies and none is undecided."""
    return all(v.complies for v in verdicts if v.status == "judged") and not any(
        v.status == "undecided" for v in verdicts
    )


def overall_verdict(verdicts: tuple[CriterionVerdict, ...]) -> str:
    """``fails``, ``undecided`` or ``complies`` (one of :data:`VERDICTS`; module docstring).

    ``complies`` exactly when :func:`verdict_complies`; ``fails`` when a judged criterion
    fails; ``undecided`` otherwise (no judged failure, an undecided criterion).
    """
    if any(v.status == "judged" and not v.complies for v in verdicts):
        return "fails"
    if any(v.status == "undecided" for v in verdicts):
        return "undecided"
    return "complies"


def combine_verdicts(verdicts: Any) -> str:
    """The verdict of several assessments (points, sensors): a fail, else undecided, else complies.

    Parameters
    ----------
    verdicts : iterable of :data:`VERDICTS` entries
    """
    got = set(verdicts)
    bad = got - set(VERDICTS)
    if bad:
        raise ValueError(f"not a verdict: {sorted(bad)}")
    return "fails" if "fails" in got else "undecided" if "undecided" in got else "complies"
