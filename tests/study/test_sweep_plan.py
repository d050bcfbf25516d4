"""The study file and the case plan: axes, defaults, [[case]] sub-products, one-line errors."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from microg.analysis import DEFAULTS
from microg.errors import InputError
from microg.study import CASE_DIMS, load_study, loads_study

BASE = """
[study]
model = "ioc"
[axes]
force = ["foot-pushoff-max", "hand-pushoff-mean"]
at = ["crew", "vertical-lab"]
direction = ["x", "-y", [0, 0.6, 0.8]]
observe = ["lab", "keel-tip", "boom-tip"]
damping = [0.002, 0.01]
[record]
duration = "60 s"
dt = "0.1 s"
max_freq = "2 Hz"
"""


def _err(text: str, tmp_path: Path | None = None) -> InputError:
    with pytest.raises(InputError) as info:
        if tmp_path is None:
            loads_study(text, filename="s.toml")
        else:
            f = tmp_path / "s.toml"
            f.write_text(text)
            load_study(f)
    return info.value


def test_full_product_shape_and_labels() -> None:
    s = loads_study(BASE, filename="s.toml")
    assert s.shape == (1, 1, 1, 2, 2, 2, 3, 3)
    # the product of the axis lengths, counted independently of the plan
    assert s.n_cases == 2 * 2 * 2 * 3 * 3
    assert s.coords["direction"] == ["x", "-y", "0 0.6 0.8"]
    assert np.allclose(s.directions[2].vector, [0, 0.6, 0.8])
    assert s.record.duration_s == 60.0 and s.record.dt_s == 0.1 and s.record.max_freq_hz == 2.0
    assert s.coords["variant"] == ["base"] and s.coords["isolator"] == ["none"]


def test_defaults_are_the_analysis_defaults() -> None:
    s = loads_study('[study]\nmodel = "ioc"\n', filename="s.toml")
    assert s.record.duration_s == DEFAULTS["duration_s"]
    assert s.record.dt_s == DEFAULTS["dt_s"]
    assert s.record.max_freq_hz == DEFAULTS["max_freq_hz"]
    assert s.record.requirement == DEFAULTS["requirement"]
    assert s.damping == (DEFAULTS["damping"],)
    assert [f.label for f in s.forces] == [DEFAULTS["force"]]
    assert s.at == ("crew",)  # the IOC model's first crew point, as analyze takes it
    assert s.observe == ("lab",)  # its experiment points


def test_blocks_tile_the_grid_exactly_once() -> None:
    s = loads_study(BASE, filename="s.toml")
    seen = np.zeros(s.shape, int)
    for b in s.blocks():
        seen[(*b.index, b.at, slice(None), b.observe)] += 1
    assert np.all(seen == 1)
    assert sum(b.n_cases for b in s.blocks()) == s.n_cases


def test_case_tables_are_sub_products() -> None:
    text = (
        BASE
        + """
[[case]]
force = "foot-pushoff-max"
at = "crew"
direction = ["x", "-y"]
[[case]]
force = "hand-pushoff-mean"
observe = "lab"
damping = 0.01
"""
    )
    s = loads_study(text, filename="s.toml")
    # first: 2 directions x 3 observe x 2 damping; second: 2 at x 3 directions; no overlap
    assert s.n_cases == 2 * 3 * 2 + 2 * 3
    mask = np.zeros(s.shape, bool)
    for b in s.blocks():
        mask[(*b.index, b.at, slice(None), b.observe)] = s.block_mask(b.index, b.at, b.observe)
    expected = np.zeros(s.shape, bool)
    for idx in itertools.product(*(range(n) for n in s.shape)):
        c = s.case(idx)
        first = (
            c["force"] == "foot-pushoff-max"
            and c["at"] == "crew"
            and c["direction"]
            in (
                "x",
                "-y",
            )
        )
        second = (
            c["force"] == "hand-pushoff-mean" and c["observe"] == "lab" and c["damping"] == 0.01
        )
        expected[idx] = first or second
    assert np.array_equal(mask, expected)


def test_variants_move_a_mass_and_validate_it() -> None:
    text = (
        BASE
        + """
[[axes.variant]]
name = "base"
[[axes.variant]]
name = "dock-fwd"
move = "main/Orbiter"
to = ["0 ft", "0 ft", "-40 ft"]
"""
    )
    s = loads_study(text, filename="s.toml")
    moved = s.variant_model(0, 1)
    orb = [pm for b in moved.bodies for pm in b.masses if pm.name == "Orbiter"][0]
    assert np.allclose(orb.position, [0, 0, -40 * 0.3048])  # 1 ft = 0.3048 m exactly
    base = [pm for b in s.variant_model(0, 0).bodies for pm in b.masses if pm.name == "Orbiter"]
    assert base[0].position[2] == pytest.approx(-126.66 * 0.3048)
    bad = text.replace('move = "main/Orbiter"', 'move = "main/Nothing"')
    e = _err(bad)
    assert e.where == "s.toml: axes.variant[1].move" and "Nothing" in str(e)


@pytest.mark.parametrize(
    ("edit", "where", "words"),
    [
        ("damping = [0.002, 0.01]\nspeed = [1]", "s.toml: axes.speed", "unknown axis"),
        ("at = []", "s.toml: axes.at", "empty axis"),
        ('observe = ["lab", "nowhere"]', "s.toml: axes.observe[1]", "'nowhere' is not in model"),
        ('force = ["no-such-activity"]', "s.toml: axes.force[0]", "unknown force"),
        ("damping = [1.5]", "s.toml: axes.damping[0]", "0 <= zeta < 1"),
        ('direction = ["x", "sideways"]', "s.toml: axes.direction[1]", ""),
    ],
)
def test_bad_input_names_file_and_field(edit: str, where: str, words: str) -> None:
    key = edit.split("=")[0].strip()
    lines = [ln for ln in BASE.splitlines() if not ln.startswith(key + " ")]
    lines.insert(lines.index("[axes]") + 1, edit)
    e = _err("\n".join(lines))
    assert e.where == where
    assert words in str(e)
    assert "\n" not in str(e)


def test_a_force_file_that_fails_names_the_field(tmp_path: Path) -> None:
    (tmp_path / "push.csv").write_text("time_s,force_N\n0,1\n1,oops\n")
    text = BASE.replace('"hand-pushoff-mean"', '"push.csv"')
    e = _err(text, tmp_path)
    assert e.where == f"{tmp_path / 's.toml'}: axes.force[1]"
    assert "push.csv" in str(e)


def test_a_relative_force_file_is_read_beside_the_study(tmp_path: Path) -> None:
    (tmp_path / "push.csv").write_text("time_s,force_N\n0,0\n1,50\n2,0\n")
    (tmp_path / "s.toml").write_text(BASE.replace('"hand-pushoff-mean"', '"push.csv"'))
    s = load_study(tmp_path / "s.toml")
    assert s.forces[1].label == "push.csv"
    assert np.array_equal(s.forces[1].history.force, [0.0, 50.0, 0.0])


def test_extra_points_are_added_to_the_station() -> None:
    text = (
        BASE.replace('"boom-tip"]', '"boom-tip", "keel-mid"]')
        + """
[[point]]
name = "keel-mid"
on = "keel"
s = "148 ft"
"""
    )
    s = loads_study(text, filename="s.toml")
    p = [p for p in s.models[0].model.points if p.name == "keel-mid"][0]
    assert np.allclose(p.position, [0, 0, 148 * 0.3048])
    bad = text.replace('on = "keel"', 'on = "nowhere"')
    assert _err(bad).where == "s.toml: point[0].on"


def test_the_record_and_the_requirement_are_checked() -> None:
    assert _err(BASE.replace('dt = "0.1 s"', 'dt = "80 s"')).where == "s.toml: record.dt"
    e = _err(BASE.replace('duration = "60 s"', 'duration = "5 s"'))
    assert e.where == "s.toml: record.duration" and "lasts until" in str(e)
    text = BASE.replace("[record]", '[record]\nrequirement = "mars"')
    assert _err(text).where == "s.toml: record.requirement"


def test_case_values_must_be_on_their_axis() -> None:
    e = _err(BASE + '\n[[case]]\nat = "boom-tip"\n')
    assert e.where == "s.toml: case[0].at" and "not a value of the at axis" in str(e)


def test_dims_are_the_contract() -> None:
    assert CASE_DIMS == (
        "model", "variant", "isolator", "damping", "force", "at", "direction", "observe"
    )  # fmt: skip


def test_the_shipped_example_study_loads() -> None:
    path = Path(__file__).resolve().parents[2] / "examples" / "study.toml"
    s = load_study(path)
    assert s.n_cases == 2 * 2 * 3 * 3 * 3 * 2 * 2
    assert s.coords["isolator"] == ["none", "soft-mount"]


def test_a_case_count_beyond_64_bits_is_refused() -> None:
    # 7 axes of 520 values: 520**7 * 1 = 1.03e19 cases, past 2**63; numpy's int64 product
    # wrapped to a negative count that passed the 100-million limit and the sweep started
    import math

    from microg.errors import InputError
    from microg.study import loads_study

    n = 520
    lst = lambda items: "[" + ", ".join(items) + "]"  # noqa: E731
    points = "\n".join(
        f'[[point]]\nname = "p{i}"\non = "keel"\ns = "{10 + i * 0.5:.1f} ft"\n' for i in range(n)
    )
    variants = (
        f'{{ name = "v{i}", move = "main/Orbiter", to = ["0 ft", "0 ft", "{-60 - i / 10:.1f} ft"]}}'
        for i in range(n)
    )
    text = f"""[study]
name = "huge"
model = "ioc"
[axes]
force = {lst(f'"crew-pushoff:f0={1 + i * 0.1:.1f}lbf,t1=0.5s"' for i in range(n))}
at = {lst(f'"p{i}"' for i in range(n))}
observe = {lst(f'"p{i}"' for i in range(n))}
direction = {lst(f'"1 {i / 600:.6f} 0"' for i in range(n))}
damping = {lst(f"{0.001 + i * 1e-5:.6f}" for i in range(n))}
isolator = {lst(f'{{ name = "s{i}", f_n = "{0.1 + i * 0.001:.3f} Hz"}}' for i in range(n))}
variant = {lst(variants)}
[record]
duration = "40 s"
dt = "0.1 s"
max_freq = "2 Hz"

{points}"""
    assert math.prod([n] * 7) > 2**63  # the case this test is about
    with pytest.raises(InputError) as info:
        loads_study(text, filename="huge.toml")
    assert "10,280,717,025,280,000,000 cases" in str(info.value)
