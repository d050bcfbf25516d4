"""Fuzzer of real NASTRAN files: OP2, OP4, BDF and punch files of tests/data/nastran, mutated.

Mutations: truncation at any byte; byte flips (1 to 8 bytes set to random values); record
length corruption (one Fortran record marker of the binary file changed); card field garbage
(one 8-character field of a bulk data line replaced by a non-number, a huge or negative
number, a continuation or replication mark, a control character).

Invariant: microg reads the mutant to a valid model, or refuses it with one line
(``InputError``/``ModelError``; the CLI: exit 2, one line on stderr).  A truncated file or a
corrupted record length of a binary file is either refused or read to exactly the original's
model (a marker the reader checks cannot slip through); a text file cut at a line is a
shorter deck (no ENDDATA is required), so it must only read consistently.  A flipped byte
in the numbers may change them (the files carry no checksum): the read must then still be
a consistent model (finite, NASTRAN's checks: symmetric matrices, a DOF map of the
matrices' size).  Never a traceback, never past the hard time limit.
"""

from __future__ import annotations

import contextlib
import io
import shutil
import struct
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_fuzz_support import Hang, fuzz_settings, one_line, record, time_limit

from microg.errors import InputError, ModelError

pytest.importorskip("pyyeti")

DATA = Path(__file__).resolve().parents[1] / "data" / "nastran"

#: seed -> (the files copied beside it, how it is read)
SEEDS: dict[str, tuple[tuple[str, ...], str]] = {
    "extseout_inboard.op2": ((), "model"),
    "rdop2gpwg_1.op2": (("rdop2gpwg_1.dat",), "model"),
    "notall6_msc2017.op2": (("notall6_msc2017.op4",), "op4"),
    "notall6_msc2017.op4": (("notall6_msc2017.op2",), "op4"),
    "inboard.op4": (("inboard.pch",), "model"),
    "inboard.pch": (("inboard.op4",), "op4"),
    "extseout_full.dat": ((), "model"),
    "nas2cam_no_se.dat": ((), "model"),
}
BINARY = [k for k in SEEDS if k.endswith((".op2", ".op4"))]
TEXT = [k for k in SEEDS if k.endswith((".dat", ".pch"))]
UNITS = "in, lbf, s"
GARBAGE = ["", "1.2.3", "nan", "inf", "-1", "-1.e+30", "99999999", "1e400", "ABCDEFGH", "+",
           "*", "=", "=2", "$", "THRU", ",,,", "\x00", "\u00e9\u00e9", "0", "1.+", "7"]  # fmt: skip


def _read(seed: str, path: Path) -> Any:
    """The model the loader reads (OP4 seeds: superelement 0 of the nas2cam pair)."""
    import microg

    target = path
    if SEEDS[seed][1] == "op4":
        target = path.with_suffix(".op4")
    kw = {"superelement": 0} if target.stem == "notall6_msc2017" else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return microg.load_model(target, units=UNITS, **kw)


def _summary(model: Any) -> tuple[np.ndarray, ...]:
    """What must not change silently: frequencies, shapes, positions."""
    if hasattr(model, "omega"):
        return (np.asarray(model.omega), np.asarray(model.phi), np.asarray(model.xyz_m))
    nodes = sorted(model.nodes, key=lambda n: n.name)
    counts = [len(getattr(model, k)) for k in ("beams", "rods", "springs", "masses")]
    return (np.array([n.position for n in nodes], float).reshape(-1, 3), np.array(counts))


def _original(seed: str) -> tuple[np.ndarray, ...]:
    with tempfile.TemporaryDirectory() as d:
        for name in (seed, *SEEDS[seed][0]):
            shutil.copy(DATA / name, Path(d) / name)
        return _summary(_read(seed, Path(d) / seed))


ORIGINAL: dict[str, tuple[np.ndarray, ...]] = {}


def _markers(data: bytes) -> list[int]:
    """Byte offsets of the Fortran record markers of a binary OP2/OP4 (empty if not one)."""
    out: list[int] = []
    for endian in "<>":
        out, i = [], 0
        while i + 4 <= len(data):
            n = struct.unpack_from(endian + "i", data, i)[0]
            if n < 0 or i + 8 + n > len(data):
                break
            out += [i, i + 4 + n]
            i += 8 + n
        if i == len(data) and out:
            return out
    return []


@st.composite
def binary_mutants(draw: Any) -> tuple[str, str, bytes]:
    seed = draw(st.sampled_from(BINARY))
    data = (DATA / seed).read_bytes()
    kind = draw(st.sampled_from(["truncate", "flip", "length"]))
    if kind == "truncate":
        return seed, kind, data[: draw(st.integers(0, len(data) - 1))]
    if kind == "length":
        marks = _markers(data)
        if marks:
            at = draw(st.sampled_from(marks))
            old = struct.unpack_from("<i", data, at)[0]
            new = draw(st.sampled_from([old + 4, old - 4, old * 2, 0, -1, 2**31 - 1, old + 1]))
            buf = bytearray(data)
            struct.pack_into("<i", buf, at, new if -(2**31) <= new < 2**31 else -1)
            return seed, kind, bytes(buf)
        kind = "flip"  # an ASCII OP4 has no markers
    buf = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        buf[draw(st.integers(0, len(buf) - 1))] = draw(st.integers(0, 255))
    return seed, kind, bytes(buf)


@st.composite
def text_mutants(draw: Any) -> tuple[str, str, bytes]:
    seed = draw(st.sampled_from(TEXT))
    lines = (DATA / seed).read_text(encoding="latin-1").splitlines(keepends=True)
    cards = [k for k, ln in enumerate(lines) if ln[:1].isalpha() or ln[:1] in "*+"]
    kind = draw(st.sampled_from(["field", "field", "truncate"]))
    if kind == "truncate":
        text = "".join(lines)
        return seed, kind, text[: draw(st.integers(0, len(text) - 1))].encode("latin-1")
    k = draw(st.sampled_from(cards))
    ln = lines[k].rstrip("\n").ljust(80)
    field = draw(st.integers(0 if "," in ln else 1, 9))
    junk = draw(st.sampled_from(GARBAGE))
    if "," in ln:
        parts = ln.rstrip().split(",")
        parts[min(field, len(parts) - 1)] = junk
        new = ",".join(parts)
    else:
        new = ln[: 8 * field] + junk[:8].ljust(8) + ln[8 * field + 8 :]
    lines[k] = new.rstrip() + "\n"
    return seed, kind, "".join(lines).encode("latin-1", "replace")


def check(seed: str, kind: str, data: bytes) -> str:
    """Run one mutant through the invariant; returns the outcome category."""
    group = "nastran " + seed.rsplit(".", 1)[1]
    if seed not in ORIGINAL:
        ORIGINAL[seed] = _original(seed)
    with tempfile.TemporaryDirectory() as d:
        for name in SEEDS[seed][0]:
            shutil.copy(DATA / name, Path(d) / name)
        path = Path(d) / seed
        path.write_bytes(data)
        try:
            with time_limit(20):
                try:
                    got = _summary(_read(seed, path))
                except (InputError, ModelError) as exc:
                    assert one_line(str(exc)), str(exc)
                    return "clean error"
        except Hang:
            record(group, "hang")
            raise
        except AssertionError:
            raise
        except Exception:
            record(group, "traceback")
            raise
        same = len(got) == len(ORIGINAL[seed]) and all(
            a.shape == b.shape and np.array_equal(a, b)
            for a, b in zip(got, ORIGINAL[seed], strict=True)
        )
        # a cut text file is a shorter deck (microg, like the punch, needs no ENDDATA): it
        # must read consistently, as a flipped byte must; a binary file's markers are checked
        binary = seed.endswith((".op2", ".op4"))
        if binary and kind in ("truncate", "length") and not same:
            record(group, "misread")
            raise AssertionError(f"{kind} of {seed} read to a different model")
        assert all(np.all(np.isfinite(a)) for a in got), "a non-finite value read silently"
        return "valid result"


@given(binary_mutants())
@fuzz_settings(n_ci=400, n_long=5_000, deadline_s=25)
def test_fuzz_mutated_op2_op4_files(case: tuple[str, str, bytes]) -> None:
    seed, kind, data = case
    record("nastran " + seed.rsplit(".", 1)[1], check(seed, kind, data))


@given(text_mutants())
@fuzz_settings(n_ci=300, n_long=5_000, deadline_s=25)
def test_fuzz_mutated_bdf_and_punch_files(case: tuple[str, str, bytes]) -> None:
    seed, kind, data = case
    record("nastran " + seed.rsplit(".", 1)[1], check(seed, kind, data))


@pytest.mark.parametrize("seed", sorted(SEEDS))
def test_seeds_read(seed: str) -> None:
    # the starting points read themselves (a mutation-free control): the same model
    assert check(seed, "truncate", (DATA / seed).read_bytes()) == "valid result"


@pytest.mark.parametrize("seed", ["extseout_inboard.op2", "notall6_msc2017.op4", "inboard.pch"])
def test_cli_gives_one_line_and_exit_2_on_a_cut_file(seed: str, tmp_path: Path) -> None:
    from microg.cli import main

    for name in SEEDS[seed][0]:
        shutil.copy(DATA / name, tmp_path / name)
    data = (DATA / seed).read_bytes()
    # binary files cut in the middle; the punch within its EXTRN entry (its first line kept)
    cut = data.index(b"\n", data.index(b"EXTRN ")) + 1 if seed.endswith(".pch") else len(data) // 2
    (tmp_path / seed).write_bytes(data[:cut])
    target = tmp_path / seed
    args = ["modes", str(target), "--units", UNITS]
    if SEEDS[seed][1] == "op4":
        target = target.with_suffix(".op4")
        args[1] = str(target)
    if target.stem == "notall6_msc2017":
        args += ["--superelement", "0"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(args)
    assert rc == 2, out.getvalue() + err.getvalue()
    assert one_line(err.getvalue()) and out.getvalue() == ""
    assert seed in err.getvalue()  # names the file


def test_include_with_a_nul_byte_is_one_line() -> None:
    # found by this fuzzer: a NUL in an INCLUDE's name made os.path raise ValueError
    deck = (DATA / "nas2cam_no_se.dat").read_text().replace("nx_dmaps", "\x00", 1)
    assert check("nas2cam_no_se.dat", "field", deck.encode()) == "clean error"
