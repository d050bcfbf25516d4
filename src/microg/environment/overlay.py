"""A prediction (a ``microg analyze`` result) beside a measurement, band by band.

The prediction is read from its JSON results (``observations[point].third_octave``), so a
measured record can be compared with a run made elsewhere or earlier.  Both must be judged
against one requirement (the same band table and limits); the bands are compared by their
worst axis, since the model's axes and the sensor's need not be aligned.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from microg.errors import InputError

__all__ = ["BandOverlay", "band_overlay", "read_prediction"]

#: relative tolerance of band centres and limits read back from JSON: it holds them to 17
#: significant digits, so anything beyond rounding is another band table
_SAME_REL = 1e-9


def read_prediction(path: str | Path, *, where: str = "predicted") -> dict[str, Any]:
    """The JSON results of a ``microg analyze`` run, checked to be one.

    Parameters
    ----------
    path : path of the results.json
    where : the parameter named in errors

    Raises
    ------
    InputError
        The file cannot be read, is not JSON, or is not a ``microg analyze`` result (a
        ``microg assess`` result is a measurement, not a prediction).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read {p}: {exc}", where=where) from None
    try:
        data = json.loads(text)
    except ValueError:
        data = None
    meta = data.get("meta") if isinstance(data, dict) else None
    if not isinstance(meta, dict) or "microg_version" not in meta:
        raise InputError(
            f"{p} is not a microg result (no meta.microg_version)",
            where=where,
            fix="give the results.json a `microg analyze --out DIR` run wrote",
        )
    if "model" not in data or "file_path" in meta:
        raise InputError(
            f"{p} is a microg assess result (a measurement), not a prediction",
            where=where,
            fix="give the results.json of `microg analyze`",
        )
    obs = data.get("observations")
    if (
        not isinstance(obs, dict)
        or not obs
        or not all(
            isinstance(o, dict) and isinstance(o.get("third_octave"), dict) for o in obs.values()
        )
    ):
        raise InputError(
            f"{p} is a microg result without band results at observed points",
            where=where,
            fix="give the results.json of `microg analyze`",
        )
    return dict(data)


def _floats(values: Any) -> np.ndarray:
    """JSON numbers (``"inf"``/None allowed) as floats."""
    return np.array([math.nan if v is None else float(v) for v in values], dtype=float)


def _choose_point(pred: dict[str, Any], point: str | None, sensor: str) -> str:
    points = list(pred["observations"])
    if point is not None:
        if point not in points:
            raise InputError(
                f"the prediction has no point {point!r} (it has {', '.join(points)})",
                where="point",
                fix="name one of its points",
            )
        return point
    if sensor in points:
        return sensor
    if len(points) == 1:
        return points[0]
    raise InputError(
        f"the prediction has {len(points)} points ({', '.join(points)}) and none is named "
        f"{sensor!r}, the measured sensor",
        where="point",
        fix="choose the predicted point with observe=POINT",
    )


@dataclass(frozen=True)
class BandOverlay:
    """A predicted and a measured 1/3-octave spectrum on the bands both have (g; Hz).

    ``predicted_g``/``measured_g`` are each band's worst-axis RMS; ``ratio`` is measured over
    predicted (above 1: the measurement exceeds the prediction).  A band is ``judged`` when
    both resolve it.
    """

    point: str
    sensor: str
    requirement: str
    predicted_path: str
    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    limit_g: np.ndarray
    predicted_g: np.ndarray
    measured_g: np.ndarray
    predicted_resolved: np.ndarray
    measured_resolved: np.ndarray

    @property
    def ratio(self) -> np.ndarray:
        """Measured over predicted band RMS, (nb,); inf where the prediction is 0."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.predicted_g > 0, self.measured_g / self.predicted_g, np.inf)

    @property
    def judged(self) -> np.ndarray:
        """(nb,) bands both the prediction and the measurement resolve."""
        return np.asarray(self.predicted_resolved, bool) & np.asarray(self.measured_resolved, bool)

    @property
    def worst_ratio_band(self) -> int | None:
        """Index of the judged band where the measurement most exceeds the prediction."""
        j = np.nonzero(self.judged)[0]
        if j.size == 0:
            return None
        return int(j[np.argmax(self.ratio[j])])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready overlay (the ``prediction`` block of ``microg assess --predicted``)."""
        from microg._io import to_jsonable

        i = self.worst_ratio_band
        return to_jsonable(
            {
                "path": self.predicted_path,
                "point": self.point,
                "sensor": self.sensor,
                "requirement": self.requirement,
                "center_hz": self.center_hz,
                "limit_g": self.limit_g,
                "predicted_g": self.predicted_g,
                "measured_g": self.measured_g,
                "ratio": [r if math.isfinite(r) else "inf" for r in self.ratio.tolist()],
                "judged": self.judged,
                "worst_ratio_band_hz": None if i is None else float(self.center_hz[i]),
                "worst_ratio": None if i is None else float(self.ratio[i]),
            }
        )

    def to_xarray(self) -> Any:
        """The overlay as an ``xarray.Dataset`` on a ``band_hz`` coordinate."""
        import xarray as xr

        return xr.Dataset(
            {
                "predicted_g": ("band_hz", self.predicted_g),
                "measured_g": ("band_hz", self.measured_g),
                "limit_g": ("band_hz", self.limit_g),
                "ratio": ("band_hz", self.ratio),
                "judged": ("band_hz", self.judged),
            },
            coords={"band_hz": self.center_hz},
            attrs={"point": self.point, "sensor": self.sensor, "requirement": self.requirement},
        )

    def plot(self, ax: Any = None) -> Any:
        """Predicted and measured band RMS against the limit (micro-g); returns the Figure."""
        from microg.plotting.environment import plot_band_overlay

        return plot_band_overlay(self, ax=ax)

    def plot_interactive(self) -> Any:
        """Predicted and measured band RMS as an interactive chart (a plotly Figure)."""
        from microg.plotting.interactive.bands import overlay_chart

        return overlay_chart(self)


def band_overlay(
    prediction: dict[str, Any],
    measurement: Any,
    *,
    point: str | None = None,
    sensor: str = "sensor",
    path: str = "",
) -> BandOverlay:
    """Pair a prediction's bands at one point with a measured assessment's, band by band.

    Parameters
    ----------
    prediction : a ``microg analyze`` JSON document (:func:`read_prediction`)
    measurement : the measured :class:`~microg.environment.assessment.Assessment`
    point : the predicted point (default: the one named like ``sensor``, or the only one)
    sensor : the measured record's name
    path : where the prediction was read from (for the output)

    Raises
    ------
    InputError
        ``point`` is not in the prediction (or is needed to choose among several), or the
        prediction was judged against another requirement or band table (``requirement``).
    """
    name = _choose_point(prediction, point, sensor)
    req = str(prediction.get("requirement"))
    if req != measurement.requirement:
        raise InputError(
            f"the prediction is judged against requirement {req!r}, the measurement against "
            f"{measurement.requirement!r}",
            where="requirement",
            fix=f"assess with requirement={req}",
        )
    to = prediction["observations"][name]["third_octave"]
    m = measurement.third_octave
    try:
        centre = _floats(to["center_hz"])
        limit = _floats(to["limit_g"])
        rms = _floats(to["rms_g"])
        resolved = np.array([bool(v) for v in to["resolved"]])
        lower, upper = _floats(to["lower_hz"]), _floats(to["upper_hz"])
    except (KeyError, TypeError, ValueError):
        raise InputError(
            f"the prediction's bands at {name!r} are incomplete", where="predicted"
        ) from None
    if not (rms.shape == centre.shape == resolved.shape == limit.shape):
        raise InputError(f"the prediction's bands at {name!r} are incomplete", where="predicted")
    # the band tables run to each record's Nyquist frequency: compare the bands both have
    pi, mi = [], []
    for k, c in enumerate(m.center_hz):
        hit = np.nonzero(np.isclose(centre, c, rtol=_SAME_REL, atol=0.0))[0]
        if hit.size:
            pi.append(int(hit[0]))
            mi.append(k)
    p_idx, m_idx = np.array(pi, int), np.array(mi, int)
    if p_idx.size == 0 or not np.allclose(limit[p_idx], m.limit_g[m_idx], rtol=_SAME_REL, atol=0.0):
        raise InputError(
            f"the prediction's bands at {name!r} are not the measurement's under requirement "
            f"{req!r} (another band table or limits)",
            where="requirement",
        )
    return BandOverlay(
        point=name,
        sensor=sensor,
        requirement=req,
        predicted_path=path,
        center_hz=centre[p_idx],
        lower_hz=lower[p_idx],
        upper_hz=upper[p_idx],
        limit_g=limit[p_idx],
        predicted_g=rms[p_idx],
        measured_g=np.asarray(m.worst_rms_g, float)[m_idx],
        predicted_resolved=resolved[p_idx],
        measured_resolved=np.asarray(m.resolved, bool)[m_idx],
    )
