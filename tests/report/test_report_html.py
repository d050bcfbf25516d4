"""The compiled-template cache of microg.report.html.

Reference: the same template compiled without a cache (Jinja's own compiler), byte for byte.
"""

from __future__ import annotations

import os

import pytest
from jinja2 import DictLoader, Environment

from microg.report.html import _BytecodeCache, environment


def _render(source: str, cache: _BytecodeCache | None) -> str:
    env = Environment(loader=DictLoader({"t.html": source}), bytecode_cache=cache)
    return env.get_template("t.html").render(x=3)


def test_cached_template_renders_as_compiled(tmp_path):
    cache = _BytecodeCache(str(tmp_path))
    first = _render("a {{ x + 1 }}", cache)  # compiled, written to the cache
    assert any(tmp_path.iterdir())
    again = _render("a {{ x + 1 }}", cache)  # loaded from the cache
    assert first == again == _render("a {{ x + 1 }}", None) == "a 4"


def test_changed_source_is_compiled_again(tmp_path):
    cache = _BytecodeCache(str(tmp_path))
    assert _render("a {{ x }}", cache) == "a 3"
    assert _render("b {{ x }}", cache) == "b 3"  # the cache checks the source's checksum


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only directory")
def test_unwritable_cache_directory_is_no_error(tmp_path):
    tmp_path.chmod(0o500)
    try:
        assert _render("a {{ x }}", _BytecodeCache(str(tmp_path))) == "a 3"
    finally:
        tmp_path.chmod(0o700)


def test_missing_cache_directory_is_no_error(tmp_path):
    # the directory removed after the cache was made (a cleaned temporary directory)
    cache = _BytecodeCache(str(tmp_path / "gone"))
    assert _render("a {{ x }}", cache) == "a 3"
    assert _render("a {{ x }}", cache) == "a 3"


def test_analysis_report_is_the_same_from_the_cache(tmp_path, monkeypatch):
    # reference: the analyze.html template compiled afresh without a cache, same result
    import microg
    import microg.report.analysis as rep

    assert environment().bytecode_cache is not None  # the package's templates are cached
    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02, isolation=False)
    figs = {name: name.encode() for name in rep.figure_builders(result)}  # nothing drawn
    pages = []
    for cache in (None, _BytecodeCache(str(tmp_path)), _BytecodeCache(str(tmp_path))):
        env = environment()
        env.bytecode_cache = cache
        monkeypatch.setattr(rep, "_analysis_template", lambda e=env: e.get_template("analyze.html"))
        pages.append(rep.render_analysis(result, figs))
    assert any(tmp_path.iterdir())  # the second render compiled and stored, the third loaded
    assert pages[0] == pages[1] == pages[2]
    assert "lab" in pages[0]
