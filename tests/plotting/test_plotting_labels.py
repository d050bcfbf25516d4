"""Figures keep their labels apart and their beams joined (the IOC model)."""

from __future__ import annotations

import itertools

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import microg


def _overlaps(fig) -> list[tuple[str, str]]:
    """Pairs of label texts (annotations of one axes) whose drawn boxes overlap."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)  # the layout and limits as saved
    pairs = []
    for ax in fig.axes:
        texts = [t for t in ax.texts if t.get_text().strip() and t.get_visible()]
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in texts]
        for (a, ba), (b, bb) in itertools.combinations(boxes, 2):
            if ba.overlaps(bb):
                pairs.append((a, b))
    return pairs


@pytest.fixture(scope="module")
def two_forces():
    # forces at the crew point and at the lab, observed at the lab: neighbours in both views
    return microg.analyze(
        "ioc",
        force=["crew-pushoff", "crew-pushoff"],
        at=["crew", "lab"],
        observe=["lab", "crew"],
        duration=20.0,
        dt=0.05,
        isolation=False,
    )


def test_model_figure_labels_do_not_overlap(two_forces) -> None:
    from microg.report.analysis import figure_builders

    fig = figure_builders(two_forces)["model.png"]()
    texts = [t.get_text() for a in fig.axes[:2] for t in a.texts]
    for name in ("crew", "lab"):  # every label still drawn
        assert any(f"force at {name}" in t or (name in t and "force" in t) for t in texts)
    assert _overlaps(fig) == []


def test_quasi_steady_map_labels_do_not_overlap() -> None:
    from microg.environment.quasisteady import quasi_steady
    from microg.models.toml import load_station

    r = quasi_steady(load_station("ioc"))
    fig = r.plot()
    texts = " ".join(t.get_text() for a in fig.axes for t in a.texts)
    for name in r.points:
        if name != "cm":
            assert name in texts
    assert _overlaps(fig) == []


@pytest.mark.parametrize("method", ["fem", "ritz"])
def test_model_figure_draws_each_beam_from_its_root_on_its_parent(method: str) -> None:
    # every component after the root body is drawn as a polyline one of whose ends is a
    # vertex of another component (its root), in both views and in every mode shape: the
    # model is drawn connected (the beams' own samples start one element from the root)
    from microg.report.analysis import figure_builders

    r = microg.analyze(
        "ioc", method=method, duration=20.0, dt=0.05, observe=["lab"], isolation=False
    )
    fig = figure_builders(r)["model.png"]()
    for ax in fig.axes:
        for line in ax.get_lines():
            xy = np.column_stack([line.get_xdata(), line.get_ydata()]).astype(float)
            cut = np.flatnonzero(np.isnan(xy[:, 0]))
            if cut.size == 0:
                continue  # a marker or a one-component line
            parts = [p for p in np.split(xy, cut) if len(p)]
            parts = [p[~np.isnan(p[:, 0])] for p in parts]
            assert len(parts) >= 4  # main body, keel, two booms
            for k, part in enumerate(parts[1:], start=1):
                others = np.concatenate([p for i, p in enumerate(parts) if i != k])
                gap = min(
                    float(np.min(np.linalg.norm(others - part[0], axis=1))),
                    float(np.min(np.linalg.norm(others - part[-1], axis=1))),
                )
                # exact: the root vertex is the parent's own sample (same float coordinates)
                assert gap == 0.0, (ax.get_title(), k, gap)
