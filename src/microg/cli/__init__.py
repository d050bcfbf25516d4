"""The ``microg`` command line.

Each subcommand lives in its own module of this package and only reads result objects
from the library; it computes nothing itself.  Errors in the user's input are printed as
one line on stderr with exit status 2 and no traceback (see :func:`main`).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys

import click

from microg import __version__
from microg.cli._common import CONTEXT_SETTINGS
from microg.errors import InputError

__all__ = ["cli", "main"]

#: subcommand name -> "module:attribute" (imported on first use, so ``microg --help`` is fast)
SUBCOMMANDS: dict[str, str] = {
    "analyze": "microg.cli.analyze:analyze",
    "reproduce": "microg.cli.reproduce:reproduce",
    "modes": "microg.cli.modes:modes",
    "locate": "microg.cli.locate:locate",
    "optimize": "microg.cli.locate:optimize",
    "isolate": "microg.cli.isolate:isolate",
    "assess": "microg.cli.assess:assess",
    "quasi-steady": "microg.cli.quasisteady:quasi_steady",
    "sweep": "microg.cli.sweep:sweep",
}


#: options renamed to the one vocabulary of the commands: old name -> what to write now
RENAMED: dict[str, str] = {
    "--crew": "--at",
    "--experiment": "--observe",
    "--point": "--observe",
    **{f"--{p}": f"--force crew-pushoff:{p}=..." for p in ("f0", "t1", "t13", "t14")},
}


class LazyGroup(click.Group):
    """A click group whose subcommands are imported on demand from :data:`SUBCOMMANDS`."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        names = set(super().list_commands(ctx))
        for name, target in SUBCOMMANDS.items():
            if importlib.util.find_spec(target.split(":")[0]) is not None:
                names.add(name)
        return sorted(names)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        cmd = super().get_command(ctx, cmd_name)
        if cmd is not None:
            return cmd
        target = SUBCOMMANDS.get(cmd_name)
        if target is None:
            return None
        module_name, attr = target.split(":")
        if importlib.util.find_spec(module_name) is None:
            return None
        return getattr(importlib.import_module(module_name), attr)


@click.group(cls=LazyGroup, context_settings=CONTEXT_SETTINGS)
@click.version_option(__version__, prog_name="microg")
def cli() -> None:
    """Microgravity environment of an orbiting space station.

    Predicts the acceleration that crew motion causes anywhere on a station, checks it
    against the ISS vibratory requirement, and designs experiment isolation.
    """


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the CLI, turning input errors into one line and exit status 2.

    Run as the process (``argv`` None: the ``microg`` script, ``python -m microg``), BLAS
    starts on one thread unless the user set a thread count (:func:`one_blas_thread`).
    """
    if argv is None:
        one_blas_thread()
    return _run(argv)


#: environment variables by which a user sets the BLAS thread count
BLAS_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")


def one_blas_thread() -> bool:
    """Start BLAS on one thread in this process, unless the user chose a count; whether it did.

    The ``microg`` commands' dense problems are small (the IOC model: 240 coordinates), and
    OpenBLAS's second thread then only contends with the first.  Only before numpy is
    imported (OpenBLAS reads the variables when it loads), and never when any of
    :data:`BLAS_ENV` is set: the user's own setting wins.  Child processes inherit them.
    """
    if "numpy" in sys.modules or any(os.environ.get(v) for v in BLAS_ENV):
        return False
    for name in BLAS_ENV[1:]:  # whichever BLAS numpy and scipy were built with
        os.environ[name] = "1"
    return True


def _run(argv: list[str] | None) -> int:
    """:func:`main`'s body: warnings gathered, each shown as one line after a success only."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        status = _status(argv)
    if status == 0:
        seen: set[str] = set()
        for w in caught:
            line = f"microg: warning: {_one_line(str(w.message))[:300]} ({w.category.__name__})"
            if line not in seen:
                seen.add(line)
                click.echo(line, err=True)
    return status


def _status(argv: list[str] | None) -> int:
    """The command run, every error turned into one line and a status."""
    try:
        status = cli.main(args=argv, prog_name="microg", standalone_mode=False)
    except click.exceptions.NoSuchOption as exc:
        hint = f"; did you mean {', '.join(exc.possibilities)}?" if exc.possibilities else ""
        if exc.option_name in RENAMED:
            hint = f"; it is now {RENAMED[exc.option_name]}"
        click.echo(f"microg: error: no such option {exc.option_name}{hint} (see --help)", err=True)
        return 2
    except click.exceptions.MissingParameter as exc:
        click.echo(f"microg: error: {_one_line(exc.format_message())} (see --help)", err=True)
        return 2
    except click.exceptions.BadParameter as exc:
        name = exc.param.opts[0] if exc.param is not None and exc.param.opts else exc.param_hint
        click.echo(f"microg: error: {name}: {_one_line(exc.message)}", err=True)
        return 2
    except click.exceptions.UsageError as exc:
        click.echo(f"microg: error: {_one_line(exc.format_message())} (see --help)", err=True)
        return 2
    except InputError as exc:
        click.echo(f"microg: error: {_one_line(str(exc))}", err=True)
        return 2
    except click.exceptions.Abort:
        click.echo("microg: aborted", err=True)
        return 1
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.ClickException as exc:
        click.echo(f"microg: error: {_one_line(exc.format_message())}", err=True)
        return exc.exit_code
    except BrokenPipeError:
        return 1
    except (MemoryError, RecursionError) as exc:
        click.echo(
            f"microg: error: {_command(argv)}: the input is too large for this machine "
            f"({type(exc).__name__}); reduce the model or the request",
            err=True,
        )
        return 2
    except KeyboardInterrupt:
        click.echo("microg: interrupted", err=True)
        return 130
    except Exception as exc:  # the funnel: a defect, never a traceback
        click.echo(
            f"microg: internal error in {_command(argv)} ({type(exc).__name__}: "
            f"{_one_line(str(exc))[:300]}); this is a defect of microg, not of your input: "
            "please report it with the command line",
            err=True,
        )
        return 3
    # without standalone mode, click returns a command's ``Exit`` status instead of raising it
    return status if isinstance(status, int) and not isinstance(status, bool) else 0


def _command(argv: list[str] | None) -> str:
    """The subcommand being run, for error messages."""
    args = sys.argv[1:] if argv is None else argv
    for a in args:
        if not a.startswith("-"):
            return f"'microg {a}'"
    return "'microg'"


def _entry() -> None:  # pragma: no cover - used by ``python -m microg``
    sys.exit(main())
