"""Benchmark of the active-isolation design against the python-control calls it wraps.

For the ``aris`` preset: the whole ``design_active`` (design, both closed loops, margins of the
12 loops, curves, noise floor, and with a record the time response and the two band tables) at
several sizes, beside the python-control calls alone on the same designed isolator in the same
process: ``frequency_response`` of the closed loop at the curves' frequencies and
``forced_response`` of the record.  The ratio says what microg adds to them (the design search,
the margins, the assessments).

Sizes: frequency points 200, 1000, 5000 (no record); record lengths 50, 200, 800 s at 100 Hz.
The H2 design (``controller="h2"``, target ``aris``) beside the ``control.h2syn`` calls alone
of its six chosen channel weights (its scan synthesises a grid of weights per channel).

Run: ``.venv/bin/python benchmarks/bench_active.py`` (about a minute).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np


def _best(fn: Callable[[], Any], repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return float(best)


def main() -> None:
    """Print design_active's time and its ratio to the python-control calls, per size."""
    import control as ct

    from microg.isolation import design_active
    from microg.isolation.active import verify

    ref = design_active("aris")
    cl = verify.closed_loop(ref.plant, ref.controller)
    print(f"{'size':>22} {'design_active s':>16} {'control calls s':>16} {'ratio':>8}")
    for nf in (200, 1000, 5000):
        f = np.geomspace(1e-4, 300.0, nf)
        t_d = _best(lambda f=f: design_active("aris", freq_hz=f), 2)
        w = 2 * np.pi * f
        t_c = _best(lambda w=w: cl.frequency_response(w))
        print(f"{f'{nf} frequencies':>22} {t_d:16.3f} {t_c:16.4f} {t_d / t_c:8.1f}")
    sub = verify._select(18, range(3)) * cl * verify._inputs(21, range(3))
    for dur in (50.0, 200.0, 800.0):
        t = np.arange(0.0, dur + 0.005, 0.01)
        a = np.zeros((3, t.size))
        a[0] = 1e-4 * np.sin(2 * np.pi * 0.16 * t)
        t_d = _best(lambda t=t, a=a: design_active("aris", timepts=t, base_accel=a), 2)
        t_c = _best(lambda t=t, a=a: ct.forced_response(sub, t, a))
        print(f"{f'{dur:g}-s record':>22} {t_d:16.3f} {t_c:16.4f} {t_d / t_c:8.1f}")
    try:
        import slycot  # noqa: F401
    except ImportError:
        print(f"{'h2 design':>22} skipped (slycot missing: the h2 extra)")
        return
    from microg.isolation.active import h2
    from microg.isolation.active.target import target_by_name

    r = design_active("aris", controller="h2", target="aris")
    rhos = [
        float(x) for x in r.controller.notes[0].split(": ", 1)[1].replace(",", "").split()[1::2]
    ]
    w = h2._weight(target_by_name("aris"), r.plant)
    plants = [h2.channel_plant(r.plant, i, rhos[i], w)[0] for i in range(6)]
    t_d = _best(lambda: design_active("aris", controller="h2", target="aris"), 1)
    t_c = _best(lambda: [ct.h2syn(p, 2, 1) for p in plants])
    print(f"{'h2 design':>22} {t_d:16.3f} {t_c:16.4f} {t_d / t_c:8.1f}")


if __name__ == "__main__":
    main()
