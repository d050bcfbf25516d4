"""What the analyze report shows: no empty tables, no dangling headers, numbers kept whole."""

from __future__ import annotations

import re

import pytest

import microg
from microg.report.analysis import report_files


@pytest.fixture(scope="module")
def sources_page() -> str:
    r = microg.analyze("ioc", sources="example", observe=["lab"])
    return report_files(r)["report.html"]


def test_sources_report_has_no_empty_force_or_point_table(sources_page: str) -> None:
    # the --sources run has no time-domain force and no time-domain observation: the page
    # says so instead of tables with headers and no rows
    assert '<th class="l">force</th>' not in sources_page
    assert "No time-domain force in this run" in sources_page
    assert "No time-domain response in this run" in sources_page
    assert "-s interval margin" not in sources_page and "worst -s" not in sources_page
    for table in re.findall(r"<table>(.*?)</table>", sources_page, flags=re.S):
        assert "<td" in table  # every table has rows


def test_numeric_cells_do_not_wrap(sources_page: str) -> None:
    assert re.search(r"td:not\(\.l\)\s*\{\s*white-space:\s*nowrap;", sources_page)


def test_time_domain_report_names_the_interval() -> None:
    r = microg.analyze("ioc", duration=40.0, dt=0.02, observe=["lab"], isolation=False)
    page = report_files(r)["report.html"]
    iv = r.observations["lab"].interval["interval_s"]
    assert f"worst {iv}-s interval margin" in page


def test_each_point_lists_its_verdict_per_criterion() -> None:
    # a 20-s record: judged bands, undecided unresolved bands, reported-only criteria; the
    # page's rows are the JSON's criteria, in order, and the isolation line names its status
    r = microg.analyze("ioc", duration=20.0, dt=0.02, observe=["lab"])
    page = report_files(r)["report.html"]
    crit = r.to_dict()["observations"]["lab"]["criteria"]
    i = page.index("<b>Verdict per criterion</b> at lab")
    section = page[i : page.index("</table>", i)]
    rows = re.findall(r"<tr><td class=\"l\">(.*?)</td>", section)
    assert rows == [c["name"] for c in crit]
    assert "undecided" in section and "reported only" in section
    status = r.observations["lab"].isolation.status
    assert f"<b>Isolation</b> ({status}):" in page
    # each row's result is the one wording of every page (criterion_verdict) and its source
    from html import escape

    from microg.report.environment import criterion_verdict

    cells = re.findall(r"<tr><td class=\"l\">.*?</tr>", section, re.S)
    for c, row in zip(crit, cells, strict=True):
        text, css = criterion_verdict(c)
        assert f'<td class="l {css}">{escape(text)}</td>' in row, row
        assert row.endswith(f'<td class="l">{escape(c["source"])}</td></tr>'), row
    # the point's and the page's verdict: undecided (no judged fail), never "do NOT comply"
    assert r.observations["lab"].verdict == r.verdict == "undecided"
    assert "do NOT comply" not in page and "does not comply" not in page
    assert "undecided: no observed point fails a judged criterion" in page
    # a 100-s interval in a 20-s record: the interval column says why it is empty
    assert r.observations["lab"].interval["count"] == 0
    assert "none: the record is shorter than the interval" in page
    # the notebook's table says the same word
    nb = r._repr_html_()
    assert "<td>undecided (the record cannot decide a criterion)</td>" in nb


def test_the_fitted_mass_note_lists_as_many_items_as_it_counts(sources_page: str) -> None:
    # the IOC model's port and starboard arrays share names: the note's count and its list
    # agree (each name with how many items carry it)
    model = microg.load_model("ioc")
    fitted = [pm.name for pm in model.all_masses() if pm.fitted]
    note = next(n for n in microg.analyze("ioc", sources="example", observe=["lab"]).notes
                if "mass items" in n)  # fmt: skip
    listed = note.split("model file: ", 1)[1].split(");", 1)[0]
    assert len(fitted) > len(set(fitted))  # the case in point: shared names
    for name in set(fitted):
        k = fitted.count(name)
        counted = re.findall(re.escape(name) + r" \((\d+) items\)", listed)
        assert counted == ([str(k)] if k > 1 else []) and name in listed, name
    assert note.startswith(f"{len(fitted)} mass items")
    assert listed in sources_page
