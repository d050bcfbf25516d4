"""HTML reports: render result objects into one self-contained page (figures embedded).

The report reads result objects only; it computes nothing.
"""

from __future__ import annotations

from jinja2 import Environment, PackageLoader, StrictUndefined, select_autoescape

from microg import __version__
from microg._io import to_jsonable
from microg.seed.reproduce import Reproduction

__all__ = ["render_reproduction", "environment"]


def environment() -> Environment:
    """The Jinja environment over ``microg/report/templates``."""
    return Environment(
        loader=PackageLoader("microg.report", "templates"),
        autoescape=select_autoescape(["html"]),
        undefined=StrictUndefined,
    )


def render_reproduction(
    rep: Reproduction, fig3_uri: str, fig4_uri: str, response_uri: str | None = None
) -> str:
    """HTML of the reproduction with Figures 3, 4 and the point response as data URIs."""
    data = to_jsonable(rep.contract())
    tmpl = environment().get_template("reproduce.html")
    return tmpl.render(
        version=__version__,
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
