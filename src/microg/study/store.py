"""The results of a sweep as one zarr store, written block by block as they are computed.

Layout (zarr format 2, consolidated metadata; ``xarray.open_zarr(DIR/results.zarr)`` reads it
as one labelled Dataset):

* one dimension per axis of the study (:data:`~microg.study.cases.CASE_DIMS`), plus ``axis``
  (x, y, z) and ``band`` (the requirement's 1/3-octave bands below Nyquist, by centre, Hz);
* variables ``peak_accel_g``, ``rms_accel_g`` (magnitude), ``peak_accel_g_axis``,
  ``rms_accel_g_axis`` (per axis), ``band_rms_g`` (per axis and band), ``margin`` (the worst
  ``limit / band RMS`` over the judged bands and axes), ``complies``, ``peak_certified`` (the
  peaks are the certified exact maxima, searched where the verdict may depend on them or for
  every case with ``[record] peaks = "exact"``; else the sampled record's) and ``computed``
  (the case is in the plan and its block is written); band coordinates ``band_lower_hz``,
  ``band_upper_hz``, ``limit_g`` and ``judged`` (the bands the record resolves);
* one chunk per variable and block (:meth:`~microg.study.cases.Study.block`): a block's values
  are written whole, by one writer (the process that runs the sweep), ``computed`` last;
* ``sweep/done`` (a zarr array beside the Dataset, one flag per block id) records the finished
  blocks; a block is marked done only after its values are written, so a sweep that stops
  is resumed from the blocks not marked (they are recomputed whole);
* ``sweep`` attributes: the modes of each solved variant and the sweep's state.

Memory is bounded by one block whatever the size of the study.  Unwritten chunks read as
their fill value (NaN, False): a partial store is readable at any time.
"""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path
from typing import Any

import numpy as np

from microg._io import to_jsonable
from microg.errors import InputError
from microg.study.cases import CASE_DIMS, Block, Study

__all__ = ["VARIABLES", "STORE_NAME", "SweepStore", "band_table"]

#: name of the store inside the output directory
STORE_NAME = "results.zarr"
#: variable -> (extra dims, dtype, units, description)
VARIABLES: dict[str, tuple[tuple[str, ...], str, str, str]] = {
    "peak_accel_g": ((), "float64", "g", "peak of the acceleration magnitude (sampled record)"),
    "rms_accel_g": ((), "float64", "g", "RMS of the acceleration magnitude over the record"),
    "peak_accel_g_axis": (("axis",), "float64", "g", "peak of |acceleration| per axis"),
    "rms_accel_g_axis": (("axis",), "float64", "g", "RMS of the acceleration per axis"),
    "band_rms_g": (("axis", "band"), "float64", "g", "1/3-octave band RMS per axis"),
    "margin": ((), "float64", "1", "worst limit / band RMS over the judged bands and axes"),
    "complies": ((), "bool", "", "the band verdict (and verified transient criteria)"),
    "peak_certified": (
        (),
        "bool",
        "",
        "the peaks are the certified exact maxima (else the sampled record's)",
    ),
    "computed": ((), "bool", "", "the case is in the plan and has been computed"),
}


def band_table(study: Study) -> dict[str, np.ndarray]:
    """The bands of the results: centres, edges, limits (g) and which the record resolves."""
    from microg.environment.metrics import acceleration_psd, band_rms
    from microg.environment.requirements import requirement

    t = study.record.timepts
    req = requirement(study.record.requirement)
    grid = acceleration_psd(t, np.zeros((1, t.size)))
    br = band_rms(grid, req.bands)
    keep = req.bands.lower_hz < grid.nyquist_hz
    return {
        "center_hz": np.asarray(br.bands.center_hz, float),
        "lower_hz": np.asarray(br.bands.lower_hz, float),
        "upper_hz": np.asarray(br.bands.upper_hz, float),
        "limit_g": np.asarray(req.limit_g, float)[keep],
        "judged": np.asarray(br.resolved, bool),
    }


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


class SweepStore:
    """A sweep's zarr store: created for a study, or reopened to resume it.

    Parameters
    ----------
    study : the Study
    path : the store's directory (``DIR/results.zarr``), or None for memory
    restart : discard an existing store of another study (else that is an error)
    where : name of the output parameter in errors
    """

    def __init__(
        self, study: Study, path: str | Path | None, *, restart: bool = False, where: str = "out"
    ):
        import zarr

        self.study = study
        self.path = None if path is None else Path(path)
        self.where = where
        self.resumed = False
        if self.path is None:
            self._store: Any = zarr.storage.MemoryStore()
            self._create()
        elif (self.path / ".zgroup").is_file() and not restart:
            self._store = str(self.path)
            self._check_same()
            self.resumed = True
        else:
            if self.path.exists():
                import shutil

                shutil.rmtree(self.path)
            self._store = str(self.path)
            self._create()
        self._group: Any = zarr.open_group(
            self._store, mode="r+", zarr_format=2, use_consolidated=False
        )
        self._arrays: dict[str, Any] = {name: self._group[name] for name in VARIABLES}
        self._done: Any = self._group["sweep/done"]

    # ------------------------------------------------------------------ creation
    def _create(self) -> None:
        import dask.array as da
        import xarray as xr

        from microg import __version__
        from microg.environment.requirements import requirement

        s = self.study
        bands = band_table(s)
        nb = bands["center_hz"].size
        shape = s.shape
        chunks = s.chunks
        coords: dict[str, Any] = {k: np.asarray(v) for k, v in s.coords.items()}
        coords["damping"] = np.asarray(s.damping, float)
        coords["axis"] = np.array(["x", "y", "z"])
        coords["band"] = bands["center_hz"]
        coords["band_lower_hz"] = ("band", bands["lower_hz"], {"units": "Hz"})
        coords["band_upper_hz"] = ("band", bands["upper_hz"], {"units": "Hz"})
        coords["limit_g"] = ("band", bands["limit_g"], {"units": "g"})
        coords["judged"] = ("band", bands["judged"])
        sizes = {"axis": 3, "band": nb}
        data_vars: dict[str, Any] = {}
        encoding: dict[str, dict[str, Any]] = {}
        for name, (extra, dtype, units, desc) in VARIABLES.items():
            dims = (*CASE_DIMS, *extra)
            full = (*shape, *(sizes[d] for d in extra))
            ch = (*chunks, *(sizes[d] for d in extra))
            fill: Any = np.nan if dtype == "float64" else False
            arr = da.full(full, fill, dtype=dtype, chunks=ch)
            var_attrs = {"description": desc}
            if units:
                var_attrs["units"] = units
            data_vars[name] = (dims, arr, var_attrs)
            encoding[name] = {"chunks": ch}
            if dtype == "float64":
                encoding[name]["_FillValue"] = np.nan
        req = requirement(s.record.requirement)
        attrs: dict[str, Any] = {
            "title": f"microg sweep {s.name}",
            "microg_version": __version__,
            "created_utc": _now(),
            "study_file": s.file,
            "study_sha256": s.sha256,
            "fingerprint": s.fingerprint,
            "study_text": s.text,
            "study_json": json.dumps(to_jsonable(s.to_dict())),
            "requirement": req.name,
            "requirement_source": req.source,
            "duration_s": s.record.duration_s,
            "dt_s": s.record.dt_s,
            "max_freq_hz": s.record.max_freq_hz,
            "n_cases": s.n_cases,
            "n_blocks": s.n_blocks,
            "band_units": "Hz",
        }
        ds = xr.Dataset(data_vars, coords=coords, attrs=attrs)
        ds["band"].attrs["units"] = "Hz"
        ds["damping"].attrs["description"] = "modal damping ratio of the elastic modes"
        try:
            ds.to_zarr(
                self._store, mode="w", compute=False, zarr_format=2, consolidated=True,
                encoding=encoding,
            )  # fmt: skip
        except OSError as exc:
            raise InputError(
                f"cannot write the store {self.path}: {exc.strerror or exc}",
                where=self.where,
                fix="choose a writable directory with free space",
            ) from None
        import zarr

        g: Any = zarr.open_group(self._store, mode="r+", zarr_format=2, use_consolidated=False)
        sub = g.create_group("sweep")
        sub.create_array("done", shape=(max(s.n_blocks, 1),), chunks=(1,), dtype="bool",
                         fill_value=False)  # fmt: skip
        sub.attrs.update({"bases": {}, "state": "created", "updated_utc": _now()})

    def _check_same(self) -> None:
        import zarr

        try:
            g: Any = zarr.open_group(self._store, mode="r", zarr_format=2, use_consolidated=False)
            fp = g.attrs.get("fingerprint")
        except Exception:  # noqa: BLE001 - any unreadable store is "not ours"
            fp = None
        if fp != self.study.fingerprint:
            raise InputError(
                f"{self.path} holds the results of another study (or of another microg "
                "version), so this sweep cannot resume it",
                where=self.where,
                fix="give another output directory, or restart=True to discard those results",
            )

    # ------------------------------------------------------------------ state
    def done(self) -> np.ndarray:
        """(n_blocks,) bool: the blocks written whole."""
        return np.asarray(self._done[:], bool)[: self.study.n_blocks]

    def record_basis(self, key: tuple[str, str], info: dict[str, Any]) -> None:
        """Keep the modes of a solved variant in the store's attributes."""
        sub = self._group["sweep"]
        bases = dict(sub.attrs.get("bases", {}))
        bases["/".join(key)] = to_jsonable(info)
        sub.attrs.update({"bases": bases, "updated_utc": _now()})

    def bases(self) -> dict[str, Any]:
        """The modes of every variant solved so far (JSON-ready)."""
        return dict(self._group["sweep"].attrs.get("bases", {}))

    def set_state(self, state: str, **extra: Any) -> None:
        """The sweep's state (``running``, ``complete``, ``stopped``) in the attributes."""
        self._group["sweep"].attrs.update({"state": state, "updated_utc": _now(), **extra})

    def state(self) -> dict[str, Any]:
        """The sweep attributes."""
        return dict(self._group["sweep"].attrs)

    # ------------------------------------------------------------------ writing
    def write(self, block: Block, values: dict[str, np.ndarray]) -> None:
        """Write one block's values (``computed`` last), then mark the block done."""
        head = block.index
        for name in (*[n for n in VARIABLES if n != "computed"], "computed"):
            v = values[name]
            idx = (*head, block.at, slice(None), block.observe)
            self._arrays[name][idx] = v
        self._done[block.id] = True

    # ------------------------------------------------------------------ reading
    def read(self, block: Block, names: tuple[str, ...]) -> dict[str, np.ndarray]:
        """The stored values of one block (shaped as the block's results)."""
        idx = (*block.index, block.at, slice(None), block.observe)
        return {n: np.asarray(self._arrays[n][idx]) for n in names}

    def dataset(self) -> Any:
        """The results as an ``xarray.Dataset`` (lazy, chunked as stored)."""
        import xarray as xr

        return xr.open_zarr(self._store, consolidated=True)
