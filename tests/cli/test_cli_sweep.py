"""``microg sweep``: the contract, the report, reproduction of a case, one-line bad input."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from microg.cli import main

STUDY = """
[study]
name = "cli-test"
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "keel-mid"]
direction = ["x", "y"]
observe = ["lab", "keel-tip"]
damping = [0.002, 0.01]
variant = [
  { name = "base" },
  { name = "dock-fwd", move = "main/Orbiter", to = ["0 ft", "0 ft", "-60 ft"] },
]
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"
[[point]]
name = "keel-mid"
on = "keel"
s = "148 ft"
"""


def _run(capsys, args: list[str]) -> tuple[int, str, str]:
    rc = main(args)
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def study_file(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("study")
    (d / "study.toml").write_text(STUDY)
    return d / "study.toml"


@pytest.fixture(scope="module")
def run(study_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "out"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["sweep", str(study_file), "--out", str(out), "--json", "--no-progress"])
    assert rc == 0
    return out, json.loads(buf.getvalue())


def test_the_json_contract(run) -> None:
    out, d = run
    assert d["cases"] == 2 * 2 * 2 * 2 * 2 * 2
    assert 0.0 <= d["complying_fraction"] <= 1.0
    assert isinstance(d["worst"], list) and len(d["worst"]) == 2  # one per observed point
    w = d["worst"][0]
    assert set(w["case"]) == {
        "model", "variant", "isolator", "damping", "force", "at", "direction", "observe"
    }  # fmt: skip
    assert w["command"].startswith("microg analyze ")
    # worst first: the margins are sorted
    assert w["margin"] <= d["worst"][1]["margin"]


def test_the_files(run) -> None:
    out, d = run
    ds = xr.open_zarr(out / "results.zarr")
    assert int(ds.computed.sum()) == d["cases"]
    frac = float((ds.complies & ds.computed).sum() / ds.computed.sum())
    assert frac == pytest.approx(d["complying_fraction"], rel=1e-15)
    html = (out / "report.html").read_text()
    for text in ("Worst cases per observed point", "Margin over at and observe", "microg analyze",
                 "Complying fraction by axis", "data:image/png;base64,"):  # fmt: skip
        assert text in html
    assert (out / "models").is_dir()  # the moved-mass variant, for microg analyze


def test_the_command_reproduces_the_worst_case(run, capsys, tmp_path: Path) -> None:
    out, d = run
    for w in d["worst"]:
        args = shlex.split(w["command"])[1:]
        rc, text, err = _run(capsys, [*args, "--out", str(tmp_path / "a"), "--json",
                                      "--no-progress"])  # fmt: skip
        assert rc == 0, err
        ob = json.loads(text)["observations"][w["case"]["observe"]]
        # microg analyze alone on that case: the same values (see test_sweep_kernel)
        # the peak: the certified one where the sweep searched it, else the sampled record's
        peak = ob["peak_accel_g"] if w["peak_certified"] else (
            ob["peak"]["sampled_peak_accel_mps2"] / 9.80665)  # fmt: skip
        assert peak == pytest.approx(w["peak_accel_g"], rel=1e-9)
        assert ob["rms_accel_g"] == pytest.approx(w["rms_accel_g"], rel=1e-9)
        assert ob["worst_band"]["margin"] == pytest.approx(w["margin"], rel=1e-9)
        assert ob["complies"] == w["complies"]


def test_resume_prints_what_was_resumed(run, study_file, capsys) -> None:
    out, _ = run
    rc, text, err = _run(capsys, ["sweep", str(study_file), "--out", str(out), "--no-progress"])
    assert rc == 0, err
    assert "blocks resumed" in text and f"written to {out}" in text


def test_heatmap_axes(run, study_file, capsys, tmp_path: Path) -> None:
    out = tmp_path / "h"
    args = ["sweep", str(study_file), "--out", str(out), "--json", "--no-progress"]
    rc, text, err = _run(capsys, [*args, "--heatmap", "variant,force"])
    assert rc == 0, err
    hm = json.loads(text)["heatmap"]
    assert hm["dims"] == ["variant", "force"]
    assert np.asarray(hm["margin"], float).shape == (2, 2)
    rc, _, err = _run(capsys, [*args, "--heatmap", "speed,force"])
    assert rc == 2 and err.startswith("microg: error: --heatmap:")


@pytest.mark.parametrize(
    ("edit", "where"),
    [
        (("damping = [0.002, 0.01]", 'damping = [0.002, 0.01]\nspeed = ["fast"]'), "axes.speed"),
        (('at = ["crew", "keel-mid"]', "at = []"), "axes.at"),
        (('observe = ["lab", "keel-tip"]', 'observe = ["lab", "attic"]'), "axes.observe[1]"),
        (('"hand-pushoff-mean"', '"missing.csv"'), "axes.force[1]"),
    ],
)
def test_bad_study_one_line_exit_2(edit, where, tmp_path: Path, capsys) -> None:
    f = tmp_path / "bad.toml"
    f.write_text(STUDY.replace(*edit))
    rc, out, err = _run(capsys, ["sweep", str(f), "--out", str(tmp_path / "o"), "--no-progress"])
    assert rc == 2
    assert err.count("\n") == 1 and f"{f}: {where}" in err
    assert not (tmp_path / "o").exists()  # nothing written


def test_a_missing_study_file(tmp_path: Path, capsys) -> None:
    rc, _, err = _run(capsys, ["sweep", str(tmp_path / "nope.toml"), "--no-progress"])
    assert rc == 2 and "nope.toml" in err and err.count("\n") == 1


def test_a_scheduler_that_does_not_answer(study_file, tmp_path: Path, capsys) -> None:
    args = ["sweep", str(study_file), "--out", str(tmp_path / "o"), "--no-progress"]
    rc, _, err = _run(capsys, [*args, "--scheduler", "tcp://127.0.0.1:9", "--timeout", "1"])
    assert rc == 2 and err.startswith("microg: error: --scheduler:") and err.count("\n") == 1
    rc, _, err = _run(capsys, [*args, "--scheduler", "tcp://127.0.0.1:9", "--workers", "2"])
    assert rc == 2 and "--workers" in err


class _SignalOnFirstBlock:
    """A progress bar that sends the process a signal once the first block is written."""

    def __init__(self, signum: int) -> None:
        self.signum, self.n, self.sent = signum, 0, False

    def update(self, k: int) -> None:
        self.n += k
        if k and not self.sent:
            import os

            self.sent = True
            os.kill(os.getpid(), self.signum)

    def close(self) -> None:
        pass


@pytest.mark.parametrize("name", ["SIGTERM", "SIGINT"])
def test_a_signal_stop_is_never_success(name, study_file, tmp_path, capsys, monkeypatch) -> None:
    # a batch system records the job by its status: 128 + the signal's number (143, 130),
    # as a shell reports a process the signal ended; the blocks written stay and resume
    import signal

    signum = getattr(signal, name)
    # Python's own SIGINT handler (KeyboardInterrupt), whatever this process inherited: a job
    # started in the background by a non-interactive shell ignores SIGINT, and so would the
    # sweep (rightly: it was asked to)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        monkeypatch.setattr(
            "microg.cli._progress.progress_bar", lambda *a, **k: _SignalOnFirstBlock(signum)
        )
        out = tmp_path / "out"
        rc, _, err = _run(capsys, ["sweep", str(study_file), "--out", str(out), "--no-progress"])
        assert rc == 128 + signum, err
        assert "sweep stopped after" in err and "to resume" in err
        monkeypatch.undo()
        rc, _, err = _run(capsys, ["sweep", str(study_file), "--out", str(out), "--no-progress"])
        assert rc == 0, err
    finally:
        signal.signal(signal.SIGINT, previous)


def test_a_failure_part_way_exits_1(study_file, tmp_path, capsys, monkeypatch) -> None:
    from microg.study.run import SweepIncompleteError

    def stop(*a, **k):
        raise SweepIncompleteError(
            "RuntimeError: disk", done_blocks=1, total_blocks=4, done_cases=8, total_cases=32,
            store=None, resume="again",
        )  # fmt: skip

    monkeypatch.setattr("microg.study.run.sweep", stop)
    rc, _, err = _run(capsys, ["sweep", str(study_file), "--out", str(tmp_path / "o")])
    assert rc == 1 and "sweep stopped after 1 of 4 blocks" in err


def _edited_example(tmp_path: Path, old: str, new: str) -> Path:
    example = Path(__file__).resolve().parents[2] / "examples" / "study.toml"
    text = example.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "study.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "case",
    [
        # a scheduler that does not answer: refused before anything is written
        ("scheduler", None, ["--scheduler", "tcp://127.0.0.1:1", "--timeout", "0.5"]),
        # a record too coarse for the modes: found by the first modal solve
        ("record", ('dt = "0.02 s"', 'dt = "5 s"'), []),
        # a variant that moves the orbiter to 1e9 ft: the masses on one line, a mechanism,
        # found by the second variant's solve after the first variant's blocks were written
        ("variant", ('"-100 ft"]', '"-1e9 ft"]'), []),
    ],
    ids=lambda c: c[0],
)
def test_a_refused_sweep_leaves_nothing(case, tmp_path: Path, capsys) -> None:
    _, edit, extra = case
    example = Path(__file__).resolve().parents[2] / "examples" / "study.toml"
    study = example if edit is None else _edited_example(tmp_path, *edit)
    out = tmp_path / "sw"
    rc, _, err = _run(capsys, ["sweep", str(study), "--out", str(out), "--no-progress", *extra])
    assert rc == 2 and err.count("\n") == 1, err
    assert not out.exists()
    # an empty directory the user made stays, empty; a foreign file is never touched
    out.mkdir()
    rc, _, _ = _run(capsys, ["sweep", str(study), "--out", str(out), "--no-progress", *extra])
    assert rc == 2 and out.is_dir() and list(out.iterdir()) == []
