"""One vocabulary across the commands: the same options, the same defaults, the same answer.

* the same push gives the laboratory the same peak in ``analyze`` and ``optimize`` with the
  same settings (the defaults, or ``--preset report``);
* every default a command's help states is the option's true default, and the shared ones
  are :mod:`microg.defaults`'s;
* ``microg --help`` never cuts a description; every writing command says ``written to``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import click
import pytest

from microg import defaults
from microg.cli import SUBCOMMANDS, cli, main
from microg.cli._common import num

MOVABLE = ["--movable", "Horizontal lab=-91ft:-5ft"]


def _run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def _analyze_peak(capsys, tmp_path: Path, *args: str) -> float:
    out_dir = tmp_path / "run"
    rc, out, err = _run(
        capsys, "analyze", "ioc", "--observe", "lab", *args, "--out", str(out_dir), "--json"
    )
    assert rc == 0, err
    return json.loads(out)["observations"]["lab"]["peak_accel_g"]


def _optimize_start(capsys, *args: str) -> float:
    rc, out, err = _run(
        capsys, "optimize", "ioc", *MOVABLE, "--maxiter", "1", "--no-progress", "--json", *args
    )
    assert rc == 0, err
    data = json.loads(out)
    assert data["experiment_point"] == "lab" and data["crew_point"] == "crew"
    return data["objective_initial_g"]


def test_report_preset_gives_the_same_peak_in_analyze_and_optimize(capsys, tmp_path) -> None:
    # analyze (FE, 3-D, zeta 0.005) said 6.8e-05 g and optimize (Ritz, X-Z, zeta 0) 6.532e-05 g
    # for the same push: their defaults differed.  With the report's settings in both, both
    # evaluate the same modes' closed-form response (Eq. 2.18) at its peak (t = 13 s, a
    # breakpoint of the push-off), so they agree to rounding: rtol 1e-9.
    a = _analyze_peak(capsys, tmp_path, "--preset", "report")
    b = _optimize_start(capsys, "--preset", "report")
    assert a == pytest.approx(b, rel=1e-9)
    assert num(a) == "6.532e-05"


def test_default_settings_give_the_same_peak_in_analyze_and_optimize(capsys, tmp_path) -> None:
    # optimize's defaults are microg.defaults' (plane 3d, damping 0.005) on the assumed-modes
    # model; analyze --method ritz takes the same.  analyze keeps the elastic modes up to
    # --max-freq (default 10 Hz) and the optimiser all of them: with --max-freq 100 Hz both
    # use the same nine modes.  The damped response's peak is found by two searches of the
    # same closed form (analyze samples at dt and refines; the site kernel refines on its own
    # grid), each to better than 1e-6 of the peak: rtol 1e-5.
    a = _analyze_peak(capsys, tmp_path, "--method", "ritz", "--max-freq", "100 Hz")
    b = _optimize_start(capsys)
    assert a == pytest.approx(b, rel=1e-5)


def test_preset_values_are_defaults_and_given_options_win(capsys, tmp_path) -> None:
    out_dir = tmp_path / "run"
    args = ["analyze", "ioc", "--preset", "report", "--damping", "0.01", "--out", str(out_dir)]
    rc, out, err = _run(capsys, *args, "--json")
    assert rc == 0, err
    data = json.loads(out)
    assert (data["method"], data["plane"], data["damping"]) == ("ritz", "xz", 0.01)


# --------------------------------------------------------------------------- help


def _commands() -> list[tuple[str, click.Command]]:
    out: list[tuple[str, click.Command]] = []
    ctx = click.Context(cli)
    for name in SUBCOMMANDS:
        cmd = cli.get_command(ctx, name)
        assert cmd is not None
        if isinstance(cmd, click.Group):
            out += [(f"{name} {sub}", cmd.commands[sub]) for sub in cmd.commands]
        else:
            out.append((name, cmd))
    return out


def _help(name: str, cmd: click.Command) -> str:
    """The help of ``microg NAME`` as the user sees it, one option per line (no wrapping)."""
    parent = click.Context(cli, info_name="microg", **{"show_default": True})
    ctx = click.Context(cmd, parent=parent, info_name=name, terminal_width=10_000)
    ctx.max_content_width = 10_000
    return cmd.get_help(ctx)


def _option_text(text: str, opt: str) -> str:
    """The help of option ``opt``: its line and the lines it wraps onto, joined."""
    lines = text.splitlines()
    i = next(
        k
        for k, ln in enumerate(lines)
        if ln.strip().startswith(opt + " ")
        or ln.strip() == opt
        or ln.strip().startswith(opt + " /")
    )
    block = [lines[i]]
    for ln in lines[i + 1 :]:
        if ln.strip().startswith("-") or not ln.strip():
            break
        block.append(ln)
    return " ".join(b.strip() for b in block)


@pytest.mark.parametrize(
    ("name", "cmd"), _commands(), ids=lambda v: v if isinstance(v, str) else ""
)
def test_help_states_true_defaults(name: str, cmd: click.Command) -> None:
    text = _help(name, cmd)
    # hand-written defaults ("[2.2]", "[150]", "(default 1)") and open ranges ("x<=None") are gone
    assert "<=None" not in text and not re.search(r"\[\d+(\.\d+)?\]", text), text
    assert not re.search(r"\(default[ :]", text), text
    for param in cmd.params:
        if not isinstance(param, click.Option) or param.hidden or param.is_flag or param.required:
            continue
        line = _option_text(text, param.opts[0])
        m = re.search(r"\[default: (.*?)(; (?:\d|x[<>])[^\]]*)?\]$", line)
        unset = param.default in (None, ()) or type(param.default).__name__ == "Sentinel"
        if unset and not isinstance(param.show_default, str):
            assert m is None, line
            continue
        assert m, f"{name} {param.opts[0]}: no [default: ...] in {line!r}"
        shown = m.group(1)
        if isinstance(param.show_default, str):
            assert shown == param.show_default, line
        elif isinstance(param.default, Path):
            assert shown == str(param.default), line
        elif isinstance(param.default, str):
            assert shown == param.default, line
        else:
            assert float(shown) == pytest.approx(float(param.default), rel=1e-12), line


# the options whose default is one of microg.defaults', in every command that has them
SHARED = {
    "--method": defaults.METHOD,
    "--plane": defaults.PLANE,
    "--damping": defaults.DAMPING,
    "--functions": defaults.FUNCTIONS,
    "--elements": defaults.ELEMENTS,
}


@pytest.mark.parametrize("name", ["analyze", "locate", "optimize", "modes"])
def test_shared_defaults_come_from_microg_defaults(name: str) -> None:
    cmd = dict(_commands())[name]
    text = _help(name, cmd)
    found = 0
    for opt, value in SHARED.items():
        if not any(ln.strip().startswith(opt + " ") for ln in text.splitlines()):
            continue
        line = _option_text(text, opt)
        found += 1
        shown = re.search(r"\[default: ([^;\]]+)", line)
        assert shown, line
        assert shown.group(1) == (f"{value:g}" if isinstance(value, float) else str(value)), line
    assert found >= 3
    assert "--preset [report]" in text
    n_modes = next((ln for ln in text.splitlines() if ln.strip().startswith("--n-modes")), "")
    assert not n_modes or f"[default: {defaults.N_MODES} of a sparse model" in n_modes


def test_group_help_never_cuts_a_description(capsys) -> None:
    for args in (["--help"], ["isolate", "--help"]):
        rc, out, _ = _run(capsys, *args)
        assert rc == 0
        listed = out.split("Commands:")[1].strip().splitlines()
        assert listed and all(not ln.rstrip().endswith("...") for ln in listed), out


# --------------------------------------------------------------------------- output


def test_numbers_print_to_four_significant_figures() -> None:
    # a sweep printed "margin 0.026419747360652845"
    assert num(0.026419747360652845) == "0.02642"
    assert num(6.531861969236142e-05) == "6.532e-05"
    assert num(150.0) == "150" and num(float("inf")) == "inf"


def test_modes_uff_says_what_it_wrote(capsys, tmp_path) -> None:
    # `microg modes --uff FILE` wrote the file and said nothing
    path = tmp_path / "ioc.unv"
    rc, out, err = _run(capsys, "modes", "ioc", "--n-modes", "8", "--uff", str(path))
    assert rc == 0, err
    assert path.is_file() and out.rstrip().endswith(f"written to {path}")


def test_locate_force_follows_analyzes_grammar(capsys) -> None:
    # --f0 40 became --force crew-pushoff:f0=40lbf: the response is linear in f0, so every
    # peak of the map scales by 40/25 exactly (to rounding, 1e-12)
    peaks = []
    for spec in ("crew-pushoff", "crew-pushoff:f0=40lbf"):
        rc, out, err = _run(
            capsys, "locate", "ioc", "--preset", "report", "--force", spec, "--json"
        )
        assert rc == 0, err
        peaks.append([s["total_peak_g"] for s in json.loads(out)["samples"]])
    assert peaks[1] == pytest.approx([40 / 25 * p for p in peaks[0]], rel=1e-12)


@pytest.mark.parametrize(
    ("args", "now"),
    [
        (["locate", "ioc", "--crew", "crew"], "--at"),
        (["optimize", "ioc", "--experiment", "lab"], "--observe"),
        (["quasi-steady", "ioc", "--point", "lab"], "--observe"),
        (["locate", "ioc", "--f0", "40 lbf"], "--force crew-pushoff:f0=..."),
    ],
)
def test_old_option_names_say_the_new_one(capsys, args: list[str], now: str) -> None:
    rc, out, err = _run(capsys, *args)
    assert rc == 2 and out == ""
    assert err == f"microg: error: no such option {args[2]}; it is now {now} (see --help)\n"


def test_model_file_options_are_one_definition_in_every_model_command(capsys, tmp_path):
    """--subcase, --superelement and --coupled-mass: the same option (type, range or
    choices, help) in modes, analyze, locate, from cli/_common.model_file_options; given
    where they do not apply, the loader's one-line refusal names the option (exit 2)."""
    from microg.cli._common import MODEL_FILE_FLAGS

    shown = {}
    ctx = click.Context(cli)
    for name in ("modes", "analyze", "locate"):
        cmd = cli.get_command(ctx, name)
        assert cmd is not None
        opts = {p.name: p for p in cmd.params}
        for key, flag in MODEL_FILE_FLAGS.items():
            p = opts[key]
            assert p.opts == [flag]
            kind = getattr(p.type, "min", None), tuple(getattr(p.type, "choices", ()))
            shown.setdefault(key, (p.help, kind))
            assert (p.help, kind) == shown[key]
    assert shown["subcase"][1][0] == 1 and shown["superelement"][1][0] == 0
    assert shown["coupled_mass"][1][1] == ("coupled", "coupled-nx9", "consistent")
    data = Path(__file__).resolve().parents[1] / "data" / "nastran" / "cla_residual.op2"
    for cmd in (["analyze", "--out", str(tmp_path / "run")], ["locate"], ["modes"]):
        rc, out, err = _run(capsys, cmd[0], str(data), *cmd[1:], "--units", "in,lbf,s",
                            "--subcase", "2")  # fmt: skip
        assert rc == 2 and err.count("\n") == 1, err
        assert "--subcase: no modes of subcase 2 in the file (subcases: 1)" in err
        rc, out, err = _run(capsys, cmd[0], "ioc", *cmd[1:], "--superelement", "0")
        assert rc == 2 and "--superelement: applies to OP4 files only" in err, err
        rc, out, err = _run(capsys, cmd[0], "ioc", *cmd[1:], "--coupled-mass", "coupled")
        assert rc == 2 and "--coupled-mass: applies to NASTRAN decks" in err, err
