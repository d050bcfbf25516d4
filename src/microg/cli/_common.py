"""What every ``microg`` command shares: help settings, ``--preset``, numbers and output lines.

* :data:`CONTEXT_SETTINGS`: ``-h``/``--help`` and ``[default: ...]`` shown for every option
  (set once on the ``microg`` group; subcommands inherit it).
* :func:`preset_option`: ``--preset NAME`` applies a named group of settings of
  :data:`microg.defaults.PRESETS` as the command's defaults; options given on the command
  line still win.
* :func:`num`: every number a command prints, to 4 significant figures.
* :func:`written`: the one line a command prints after writing its outputs.
* :func:`model_file_options`: ``--subcase`` (an OP2's) and ``--superelement`` (an OP4's), the
  same in every command that reads a model.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import click
from click.core import ParameterSource

from microg import defaults
from microg.defaults import PRESETS, preset

__all__ = [
    "CONTEXT_SETTINGS",
    "Option",
    "given",
    "model_file_options",
    "num",
    "preset_option",
    "written",
]

#: the help of every command: ``-h`` as well as ``--help``, and every default shown
CONTEXT_SETTINGS: dict[str, Any] = {"help_option_names": ["-h", "--help"], "show_default": True}


def num(value: float | int, digits: int = 4) -> str:
    """``value`` to ``digits`` significant figures (``6.532e-05``, ``0.02642``, ``150``)."""
    x = float(value)
    if not math.isfinite(x):
        return str(x)
    return f"{x:.{digits}g}"


def written(path: Path | str, *more: Path | str) -> None:
    """Print ``written to PATH`` (and each further path), the line of every writing command."""
    click.echo("written to " + ", ".join(str(p) for p in (path, *more)))


def given(ctx: click.Context, name: str) -> bool:
    """Whether the user gave parameter ``name`` (on the command line or in the environment)."""
    source = ctx.get_parameter_source(name)
    return source in (ParameterSource.COMMANDLINE, ParameterSource.ENVIRONMENT)


class Option(click.Option):
    """An option whose computed default (``show_default="..."``) is shown as written.

    click puts a text default in parentheses (``[default: (the model's first crew point)]``);
    this shows ``[default: the model's first crew point]`` like every other default.
    """

    def get_help_extra(self, ctx: click.Context) -> Any:
        """The help extras of click, a text default without its parentheses."""
        extra = super().get_help_extra(ctx)
        if isinstance(self.show_default, str) and "default" in extra:
            extra["default"] = self.show_default
        return extra


def preset_option(params: Mapping[str, str]) -> Callable[[Any], Any]:
    """The ``--preset`` option of a command.

    ``params`` maps a preset key (``method``, ``plane``, ``damping``, ``functions``) to the
    command's parameter name; keys the command does not have are skipped.  The option is
    eager: it sets the context's ``default_map`` before the other options are read, so the
    preset replaces their defaults and an option given on the command line wins.
    """

    def apply(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
        if value is None:
            return None
        settings = preset(value)
        ctx.default_map = {
            **(ctx.default_map or {}),
            **{params[k]: v for k, v in settings.items() if k in params},
        }
        return value

    shown = "; ".join(
        f"{name}: "
        + ", ".join(
            f"--{k} {v:g}" if isinstance(v, float) else f"--{k} {v}"
            for k, v in values.items()
            if k in params
        )
        for name, values in PRESETS.items()
    )
    return click.option(
        "--preset",
        type=click.Choice(sorted(PRESETS)),
        default=None,
        is_eager=True,
        expose_value=False,
        callback=apply,
        help=f"Named settings, used as this command's defaults (given options win). {shown}.",
    )


#: the most frame elements per beam any command accepts
MAX_ELEMENTS = 10000


def discretisation_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """``--functions`` (Ritz) and ``--elements`` (FE), the same in every command.

    Imported when a command's module loads, not with ``microg.cli`` (numpy must not load before
    :func:`microg.cli.one_blas_thread`).
    """
    from microg.cli.params import Integer
    from microg.structure.ritz import MAX_FUNCTIONS

    command = click.option(
        "--elements",
        type=Integer(1, MAX_ELEMENTS),
        default=defaults.ELEMENTS,
        help="--method fem: elements per beam (more where masses and joints cut a beam).",
    )(command)
    return click.option(
        "--functions",
        type=Integer(1, MAX_FUNCTIONS),
        default=defaults.FUNCTIONS,
        help="--method ritz: admissible functions per beam and deformation kind.",
    )(command)


#: the options of :func:`model_file_options`, by parameter name (for ``flag_errors``)
MODEL_FILE_FLAGS = {
    "subcase": "--subcase",
    "superelement": "--superelement",
    "coupled_mass": "--coupled-mass",
}


def model_file_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """``--subcase``, ``--superelement`` and ``--coupled-mass``: how a NASTRAN file is read.

    The same in every command that reads a model (``modes``, ``analyze``, ``locate``),
    passed to :func:`microg.load_model` as ``subcase=``, ``superelement=`` and
    ``coupled_mass=``.
    """
    command = click.option(
        "--coupled-mass",
        "coupled_mass",
        type=click.Choice(["coupled", "coupled-nx9", "consistent"]),
        default=None,
        cls=Option,
        show_default=f"{defaults.NASTRAN_COUPLED_MASS} (Simcenter Nastran 2020.2)",
        help="A NASTRAN deck with PARAM,COUPMASS > 0: NASTRAN's coupled CBAR mass as "
        "Simcenter 2020.2 (coupled) or NX 9.1 (coupled-nx9) forms it, or microg's "
        "consistent mass.",
    )(command)
    command = click.option(
        "--superelement",
        type=click.IntRange(min=0),
        default=None,
        help="An OP4 holding the matrices of several superelements (nas2cam's SE_START "
        "blocks, named by the OP2 beside it): the superelement to read.",
    )(command)
    return click.option(
        "--subcase",
        type=click.IntRange(min=1),
        default=None,
        help="An OP2 with modes of several subcases: the subcase to read.",
    )(command)
