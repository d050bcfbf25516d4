"""HTML reports: render result objects into one self-contained page (figures embedded).

The report reads result objects only; it computes nothing.  Compiled templates are kept in
Jinja's bytecode cache (a directory of the user's own under the system's temporary directory,
as :class:`jinja2.FileSystemBytecodeCache` makes it), checked against the template's source:
compiling ``analyze.html`` takes ~0.1 s, loading it from the cache ~1 ms.
Without a usable cache directory the templates are compiled as before.
"""

from __future__ import annotations

import base64
import contextlib
from functools import lru_cache
from typing import TYPE_CHECKING, Any

from jinja2 import (
    BytecodeCache,
    Environment,
    FileSystemBytecodeCache,
    PackageLoader,
    StrictUndefined,
    select_autoescape,
)
from jinja2.bccache import Bucket

from microg import __version__
from microg._io import to_jsonable

if TYPE_CHECKING:  # the seed reproduction loads only for its own report (~0.1 s)
    from microg.seed.reproduce import Reproduction

__all__ = [
    "VERDICT_WORDS",
    "chart_fragment",
    "criterion_verdict",
    "environment",
    "id_ranges",
    "plotly_js",
    "png_data_uri",
    "render_reproduction",
]


def png_data_uri(png: bytes) -> str:
    """A ``data:image/png;base64,...`` URI for embedding ``png`` in HTML."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


@lru_cache(maxsize=1)
def plotly_js() -> str:
    """plotly.js itself (~4.8 MB), inlined once in a page's head: the page works offline."""
    from plotly.offline import get_plotlyjs

    return str(get_plotlyjs())


def chart_fragment(fig: Any, div_id: str) -> str:
    """A plotly figure as an HTML fragment for a page whose head inlines :func:`plotly_js`.

    Parameters
    ----------
    fig : plotly.graph_objects.Figure
    div_id : the figure's element id, unique in the page
    """
    from microg.plotting.interactive import plotly_html

    return plotly_html(fig, div_id=div_id, include_plotlyjs=False)


def id_ranges(ids: list[str]) -> list[tuple[str, str]]:
    """Errata ids as (label, anchor) runs.

    ``["E9", "E10", "E11", "E14"]`` -> ``[("E9-E11", "E9"), ("E14", "E14")]``.

    Parameters
    ----------
    ids : list of str
        Ids ``E<n>`` in increasing order.
    """
    nums = [int(i[1:]) for i in ids if i[:1] == "E" and i[1:].isdigit()]
    runs: list[list[int]] = []
    for n in nums:
        if runs and n == runs[-1][-1] + 1:
            runs[-1].append(n)
        else:
            runs.append([n])
    return [(f"E{r[0]}" if len(r) == 1 else f"E{r[0]}-E{r[-1]}", f"E{r[0]}") for r in runs]


class _BytecodeCache(FileSystemBytecodeCache):
    """Jinja's file cache, where a cache file that cannot be read or written is no error."""

    def load_bytecode(self, bucket: Bucket) -> None:
        """Fill ``bucket`` from its file, if that can be read (else it stays empty)."""
        try:
            super().load_bytecode(bucket)
        except OSError:
            bucket.reset()

    def dump_bytecode(self, bucket: Bucket) -> None:
        """Write ``bucket`` to its file, if that can be done (else nothing is cached)."""
        with contextlib.suppress(OSError):
            super().dump_bytecode(bucket)


@lru_cache(maxsize=1)
def _bytecode_cache() -> BytecodeCache | None:
    """Jinja's per-user bytecode cache directory, or None where it cannot be made."""
    try:
        return _BytecodeCache(pattern="__microg_jinja2_%s.cache")
    except (OSError, RuntimeError):  # no temporary directory of the user's own
        return None


def criterion_verdict(c: dict[str, Any]) -> tuple[str, str]:
    """(verdict text, CSS class) of one criterion of the JSON ``criteria`` list, from its fields.

    The words are :meth:`microg.environment.criteria.CriterionVerdict.line`'s: ``judged`` is
    "complies" or "fails", ``reported`` adds "reported only" (its limit does not enter the
    verdict), ``undecided`` says so.

    Parameters
    ----------
    c : one entry of an observation's ``criteria`` (``status``, ``complies``, ``margin``)
    """
    if c.get("status") == "undecided" or c.get("complies") is None:
        return "undecided", "undecided"
    margin = c.get("margin")
    m = f" (margin {margin:.3g})" if isinstance(margin, int | float) else ""
    if c.get("status") == "judged":
        return ("complies" + m, "pass") if c["complies"] else ("fails" + m, "fail")
    if c["complies"]:
        return "reported only: within its limit" + m, ""
    return "reported only: exceeds its limit" + m, "warn"


#: an assessment's verdict (``complies``/``fails``/``undecided``) as a page says it, with its
#: CSS class
VERDICT_WORDS = {
    "complies": ("complies", "pass"),
    "fails": ("does NOT comply", "fail"),
    "undecided": ("undecided: no judged criterion fails, but the record cannot decide one", "warn"),
}


def environment() -> Environment:
    """The Jinja environment over ``microg/report/templates`` (compiled templates cached)."""
    env = Environment(
        loader=PackageLoader("microg.report", "templates"),
        autoescape=select_autoescape(["html"]),
        undefined=StrictUndefined,
        bytecode_cache=_bytecode_cache(),
    )
    env.filters["id_ranges"] = id_ranges
    env.globals["criterion_verdict"] = criterion_verdict
    env.globals["verdict_words"] = VERDICT_WORDS
    return env


def render_reproduction(
    rep: Reproduction, fig3_uri: str, fig4_uri: str, response_uri: str | None = None
) -> str:
    """HTML of the reproduction with Figures 3, 4 and the point response as data URIs.

    Parameters
    ----------
    rep : Reproduction
    fig3_uri, fig4_uri : str
        PNG data URIs of Figures 3 and 4.
    response_uri : str, optional
        PNG data URI of the response at the observation point.
    """
    from microg.seed.ioc import printed_literals
    from microg.seed.nomenclature import NOMENCLATURE

    data = to_jsonable(rep.contract())
    tmpl = environment().get_template("reproduce.html")
    return tmpl.render(
        version=__version__,
        seed=data["seed_report"],
        meta=data["meta"],
        agreement=rep.agreement,
        comparisons=rep.comparisons,
        nomenclature=NOMENCLATURE,
        lit=printed_literals(),
        opts=data["options"],
        table4=rep.table4,
        appendix=to_jsonable(rep.appendix_c),
        errata=rep.errata,
        model_mass=data["model_mass_properties"],
        rigid_g=next(iter(rep.table4.values())).rigid_translation_accel_g,
        fig3=fig3_uri,
        fig4=fig4_uri,
        response_fig=response_uri,
        amax=list(zip(rep.curves.omega.tolist(), rep.curves.amax.tolist(), strict=True)),
    )
