"""The bounded memo of kept results, and frozen objects' state after pickling."""

from __future__ import annotations

import pickle
import threading

import numpy as np
import pytest

from microg._kept import Kept, frozen_state


def test_the_least_recently_used_entry_goes_first() -> None:
    kept: Kept[str, int] = Kept(2)
    kept.put("a", 1)
    kept.put("b", 2)
    assert kept.get("a") == 1  # "a" is now the most recent
    kept.put("c", 3)
    assert kept.get("b") is None and kept.get("a") == 1 and kept.get("c") == 3
    assert len(kept) == 2
    kept.clear()
    assert len(kept) == 0 and kept.get("a") is None


def test_threads_reading_and_writing_at_once_raise_nothing() -> None:
    kept: Kept[int, int] = Kept(8)
    errors: list[BaseException] = []

    def work(seed: int) -> None:
        try:
            for i in range(20000):
                k = (seed * 7919 + i) % 64
                if kept.get(k) is None:
                    kept.put(k, k)
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(s,)) for s in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(kept) <= 8


def test_frozen_state_makes_arrays_read_only_and_drops_kept_results() -> None:
    state = {"x": np.arange(3.0), "_kept": "stale", "name": "n"}
    out = frozen_state(state)
    assert set(out) == {"x", "name"}
    with pytest.raises(ValueError):
        out["x"][0] = 1.0
    assert state["x"].flags.writeable  # the given state is not changed


def test_a_plant_and_a_target_after_pickling_keep_nothing_stale() -> None:
    pytest.importorskip("control")
    from microg.isolation.active.plant import plant_key
    from microg.isolation.active.presets import load_preset
    from microg.isolation.active.target import band_target

    plant, _ = load_preset("aris")
    key = plant_key(plant)
    back = pickle.loads(pickle.dumps(plant))
    assert plant_key(back) == key
    with pytest.raises(ValueError):
        back.inertia_kg_m2[0, 0] = 1.0  # read-only after the round trip too
    target = band_target({1.0: 10.0}, {1.0: (0.9, 1.1)})
    checks = target.check_freq_hz()
    again = pickle.loads(pickle.dumps(target))
    assert np.array_equal(again.check_freq_hz(), checks)
    with pytest.raises(ValueError):
        again.hi_hz[0] = 2.0
    with pytest.raises(ValueError):
        target.lo_hz[0] = 2.0  # a target's arrays are its own and read-only


def test_a_byte_limit_drops_the_oldest_and_refuses_a_heavy_entry() -> None:
    kept: Kept[int, bytes] = Kept(100, max_bytes=100, weight=len)
    for i in range(5):
        kept.put(i, b"x" * 20)  # 5 x 20 = 100 bytes: all kept
    assert len(kept) == 5
    kept.put(5, b"x" * 20)  # 120 bytes: the oldest goes
    assert kept.get(0) is None and kept.get(5) is not None and len(kept) == 5
    heavy = b"x" * 26  # more than a quarter of the limit: returned, not kept
    assert kept.put(9, heavy) is heavy and kept.get(9) is None
    kept.put(5, b"x")  # replacing an entry counts its new weight only
    for i in range(6, 10):
        kept.put(i, b"x" * 20)
    assert kept.get(5) is not None  # 1 + 4 x 20 + the others still fit after dropping
