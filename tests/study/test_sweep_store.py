"""The zarr store: streamed block by block, readable part-way, resumed without recomputing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from microg.errors import InputError
from microg.study import SweepIncompleteError, loads_study, sweep
from microg.study.kernel import run_blocks
from microg.study.plan import CASE_DIMS

TEXT = """
[study]
name = "store-test"
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean", "crew-pushoff"]
at = ["crew", "vertical-lab"]
direction = ["x", "z"]
observe = ["lab", "keel-tip"]
damping = [0.002, 0.01]
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"
"""


def _study(text: str = TEXT):
    return loads_study(text, filename="study.toml")


def _equal(a: xr.Dataset, b: xr.Dataset) -> None:
    for name in a.data_vars:
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name


@pytest.fixture(scope="module")
def reference():
    return sweep(_study()).dataset.load()


def test_the_store_is_one_labelled_dataset(tmp_path: Path, reference) -> None:
    r = sweep(_study(), tmp_path / "out")
    ds = xr.open_zarr(tmp_path / "out" / "results.zarr")  # plain xarray, no microg
    assert set(CASE_DIMS) | {"axis", "band"} == set(ds.sizes)
    for v in ("peak_accel_g", "rms_accel_g", "band_rms_g", "margin", "complies"):
        assert v in ds.data_vars
    assert ds.band_rms_g.dims[-2:] == ("axis", "band")
    assert ds.attrs["requirement"] == "iss" and ds.attrs["n_cases"] == r.study.n_cases
    _equal(ds.load(), reference)  # the directory store holds what the memory store holds


def test_a_stopped_sweep_keeps_its_blocks_and_resumes(
    tmp_path: Path, reference, monkeypatch
) -> None:
    monkeypatch.setattr("microg.study.run.TASK_CASES", 1)  # one block per task
    calls: list[int] = []

    def flaky(basis, plan, works, threads):
        calls.append(len(works))
        if len(calls) == 3:
            raise RuntimeError("disk on fire")
        return run_blocks(basis, plan, works, threads)

    out = tmp_path / "out"
    study = _study()
    total = len(list(study.blocks()))
    with pytest.raises(SweepIncompleteError) as info:
        sweep(study, out, _task_fn=flaky)
    msg = str(info.value)
    assert "disk on fire" in msg and "to resume" in msg and str(out / "results.zarr") in msg
    written = sum(calls[:2])
    assert info.value.done_blocks == written
    # the blocks written are readable part-way, and only they are marked computed
    part = xr.open_zarr(out / "results.zarr").load()
    n_done = int(part.computed.sum())
    assert n_done == info.value.done_cases > 0
    ok = part.computed.values
    assert np.array_equal(part.peak_accel_g.values[ok], reference.peak_accel_g.values[ok])
    assert np.all(np.isnan(part.peak_accel_g.values[~ok]))
    # resume: the finished blocks are not recomputed
    redone: list[int] = []

    def counting(basis, plan, works, threads):
        redone.extend(w.id for w in works)
        return run_blocks(basis, plan, works, threads)

    r = sweep(study, out, _task_fn=counting)
    assert r.resumed_blocks == written and len(redone) == total - written
    _equal(r.dataset.load(), reference)
    # a third run finds everything done and computes nothing
    again: list[int] = []
    r3 = sweep(study, out, _task_fn=lambda *a: again.append(1) or run_blocks(*a))
    assert again == [] and r3.computed_blocks == 0


def test_another_study_into_the_same_directory_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "out"
    sweep(_study(), out)
    other = _study(TEXT.replace("damping = [0.002, 0.01]", "damping = [0.005]"))
    with pytest.raises(InputError) as info:
        sweep(other, out)
    assert info.value.where == "out" and "another study" in str(info.value)
    r = sweep(other, out, restart=True)
    assert r.dataset.sizes["damping"] == 1


def test_a_foreign_directory_is_not_touched(tmp_path: Path) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(InputError) as info:
        sweep(_study(), out)
    assert info.value.where == "out"
    assert (out / "thesis.tex").read_text() == "precious"


def test_memory_is_bounded_by_a_block() -> None:
    """A block's arrays are the largest the sweep holds: (n_at, n_dir, n_obs, 3, nb) values,
    whatever the number of blocks (the chunking is one block per chunk)."""
    s = _study()
    ds = sweep(s).dataset
    chunk = ds.band_rms_g.data.chunksize
    assert chunk[:5] == (1, 1, 1, 1, 1)
    assert chunk[5:] == (s.chunks[5], s.chunks[6], s.chunks[7], 3, ds.sizes["band"])


def test_sigterm_stops_the_sweep_resumably(tmp_path):
    # a batch system's time limit sends SIGTERM: the blocks written stay, the error says how
    # to resume, and the same call then resumes them; the process's own handler is restored
    import os
    import signal

    from microg.study import load_study

    example = Path(__file__).resolve().parents[2] / "examples" / "study.toml"
    study = load_study(example)
    out = tmp_path / "out"
    sent = []

    def progress(done: int, total: int) -> None:
        if done and not sent:
            sent.append(done)
            os.kill(os.getpid(), signal.SIGTERM)

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SweepIncompleteError) as err:
        sweep(study, out, progress=progress)
    assert "terminated (SIGTERM" in str(err.value) and "to resume" in str(err.value)
    assert signal.getsignal(signal.SIGTERM) == before
    again = sweep(study, out)
    assert again.resumed_blocks > 0
    assert bool(again.dataset.computed.all())
