"""Plots say what the tables say: integrated acceleration in micro-g s, unjudged bands marked."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from microg.environment.metrics import integrated_acceleration
from microg.plotting.environment import plot_integrated
from microg.units import G0


def test_integrated_acceleration_plot_is_in_micro_g_s():
    # reference: the largest |integral| (m/s) converted by hand, 10 micro-g over 10 s = 100
    # micro-g s; 1e-12 for the running trapezoid's rounding
    t = np.arange(2001) * 0.01
    a = np.zeros((3, t.size))
    a[0] = 10e-6 * G0
    integ = integrated_acceleration(t, a, 10.0)
    fig = plot_integrated(integ)
    ax = fig.axes[0]
    assert "micro-g s" in ax.get_ylabel()
    top = max(float(np.max(np.abs(ln.get_ydata()))) for ln in ax.get_lines())
    assert top == pytest.approx(100.0, rel=1e-12)


def test_analyze_bands_panel_marks_the_bands_it_does_not_judge():
    import microg
    from microg.plotting.analysis import observation_figure

    r = microg.analyze("ioc", duration=20.0, dt=0.02, observe=["lab"], isolation=False)
    ob = r.observations["lab"]
    to = ob.assessment.third_octave
    assert not np.all(to.resolved)  # a 20-s record leaves the low bands unjudged
    fig = observation_figure(ob, kind="bands")
    ax = fig.axes[0]
    hollow = [ln for ln in ax.get_lines() if ln.get_label() == "_unjudged"]
    filled = [ln for ln in ax.get_lines() if ln.get_label() == "_judged"]
    assert hollow and filled
    assert all(ln.get_markerfacecolor() == "none" for ln in hollow)
    np.testing.assert_array_equal(hollow[0].get_xdata(), to.center_hz[~to.resolved])
    labels = ax.get_legend_handles_labels()[1]
    assert "judged bands" in labels and "not judged (hollow)" in labels
