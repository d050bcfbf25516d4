"""Tests of microg.models.bdf_cards: the bulk data tokenizer.

References: the NASTRAN Quick Reference Guide's "Bulk Data Entry format" (field widths,
continuations, real number forms), cited per test; the pyNastran cross-check of whole decks
is in ``test_bdf.py``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from microg.errors import InputError
from microg.models.bdf_cards import MAX_INCLUDE_DEPTH, _value, read_cards

pytestmark = pytest.mark.nastran


def _deck(tmp_path: Path, body: str, name: str = "deck.bdf") -> Path:
    p = tmp_path / name
    p.write_text(body)
    return p


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("", None),
        ("  12 ", 12),
        ("-3", -3),
        ("1.5", 1.5),
        ("1.", 1.0),
        (".5", 0.5),
        ("1.5-3", 1.5e-3),
        ("2.5900-3", 2.59e-3),
        ("3.0000+7", 3.0e7),
        ("1.E5", 1.0e5),
        ("-1.5D-2", -1.5e-2),
        ("1.5e+02", 150.0),
        ("MSCBML0", "MSCBML0"),
        ("rod", "ROD"),
    ],
)
def test_field_values_in_nastran_forms(text, value):
    # QRG "Bulk Data Entry format": reals need a decimal point; the exponent's E may be
    # omitted when it is signed (1.5-3 = 1.5E-3); D is a double-precision exponent
    got = _value(text)
    assert got == value and type(got) is type(value)


def test_small_large_free_fields_continuations_tabs_comments_include(tmp_path):
    (tmp_path / "sub").mkdir()
    _deck(
        tmp_path / "sub",
        "GRID    4               7.0     8.0     9.0\nINCLUDE 'more.blk'\n",
        "inc.blk",
    )
    _deck(tmp_path / "sub", "GRID,5,,1.,1.,1. $ free field with a comment\n", "more.blk")
    text = (
        "SOL 103\nCEND\nSPC = 7\nBEGIN BULK\n"
        "$ a comment line\n"
        "GRID    1       0       1.0     2.0     3.0\n"
        "GRID*   2               0               1.5-3           2.0\n"
        "*       3.0\n"
        "CONM2   21      1       0       2.5     0.0     0.0     0.0             +C1\n"
        "+C1     1.0     0.0     2.0     0.0     0.0     3.0\n"
        "CONM2   22      1\t0\t1.0\n"  # tabs: 8-column stops
        "        4.0\n"  # implicit continuation: blank first field
        "INCLUDE 'sub/inc.blk'\n"
        "ENDDATA\nGRID,99,,0.,0.,0.\n"
    )
    cards, case = read_cards(_deck(tmp_path, text))
    assert case == ["SPC = 7"]
    by = {(c.name, c.fields[1]): c for c in cards}
    assert by["GRID", 1].fields[3:6] == (1.0, 2.0, 3.0)
    assert by["GRID", 2].fields[2:6] == (0, 1.5e-3, 2.0, 3.0)  # large field, * continuation
    assert by["CONM2", 21].fields[9:15] == (1.0, 0.0, 2.0, 0.0, 0.0, 3.0)
    assert by["CONM2", 22].fields[1:4] == (22, 1, 0) and by["CONM2", 22].fields[4] == 1.0
    assert by["CONM2", 22].fields[9] == 4.0
    assert by["GRID", 4].fields[3:6] == (7.0, 8.0, 9.0) and by["GRID", 4].file.endswith("inc.blk")
    assert ("GRID", 5) in by and ("GRID", 99) not in by  # nested INCLUDE; nothing after ENDDATA
    assert by["GRID", 2].line == 7 and by["GRID", 4].line == 1


def test_include_cycle_and_depth_are_one_line_errors(tmp_path):
    # an INCLUDE of itself, and a chain deeper than MAX_INCLUDE_DEPTH, name the line
    _deck(tmp_path, "INCLUDE 'self.blk'\n", "self.blk")
    with pytest.raises(InputError, match="includes itself") as exc:
        read_cards(_deck(tmp_path, "GRID,1,,0.,0.,0.\nINCLUDE 'self.blk'\n"))
    assert str(exc.value).startswith(f"{tmp_path / 'self.blk'}:1: ")  # the file and line
    for k in range(MAX_INCLUDE_DEPTH + 1):
        _deck(tmp_path, f"INCLUDE 'd{k + 1}.blk'\n", f"d{k}.blk")
    _deck(tmp_path, "GRID,1,,0.,0.,0.\n", f"d{MAX_INCLUDE_DEPTH + 1}.blk")
    with pytest.raises(InputError, match=f"deeper than {MAX_INCLUDE_DEPTH}"):
        read_cards(_deck(tmp_path, "INCLUDE 'd0.blk'\n", "top.bdf"))
    # one level less is read
    cards, _ = read_cards(_deck(tmp_path, "INCLUDE 'd2.blk'\n", "ok.bdf"))
    assert [c.name for c in cards] == ["GRID"]


def test_a_short_free_field_line_before_its_continuation_is_padded(tmp_path):
    # each free-field line stands for one fixed-format line (QRG, "Free Field Format"): the
    # continuation's first data field is PA whatever the first line held, so this CBAR has
    # PA and PB blank and W1A = 1; unpadded, the 1 became PA, a pin flag (a silent misread).
    # Reference: the same card in fixed format, whose columns leave no doubt.
    free = tmp_path / "free.dat"
    free.write_text("BEGIN BULK\nCBAR,1,1,1,2,0.,1.\n,,,1.\nGRID*,3,,1.\n*,2.\nENDDATA\n")
    fixed = tmp_path / "fixed.dat"
    fixed.write_text(
        "BEGIN BULK\n"
        + "CBAR    1       1       1       2       0.      1.                      +\n"
        + "+                       1.\n"
        + "GRID*   3                               1.                              *\n"
        + "*       2.\n"
        + "ENDDATA\n"
    )
    (got, _), (want, _) = read_cards(free), read_cards(fixed)
    assert [c.fields for c in got] == [c.fields for c in want]
    bar = got[0].fields
    assert bar[9] is None and bar[10] is None and bar[11] == 1.0  # PA, PB blank; W1A = 1
    assert got[1].fields[:5] == ("GRID", 3, None, 1.0, None) and got[1].fields[5] == 2.0
