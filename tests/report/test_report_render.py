"""Figures drawn by forked helper processes (microg.report.render) equal those drawn in-process.

References: the in-process drawing (:func:`microg.report.analysis.figures` without a renderer)
byte for byte; Graham's list-scheduling bound for the sharing of the figures.  The fork tests
run in a fresh interpreter (a pytest process may run other threads, where the renderer
rightly refuses to fork).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from microg.report.render import FigureJob, FigureRenderer, _Queue, default_processes

SCRIPT = r"""
import json, os, sys, time
import microg
import microg.report.analysis as rep
from microg.report.render import FigureJob, FigureRenderer

def probe(payload):
    # what the helper had to import to unpickle an analysis (its sparse matrices omitted)
    loaded = [m for m in ("scipy", "pydantic", "pint") if m in sys.modules]
    kinds = sorted({type(payload.structure.mass).__name__, type(payload.modes).__name__})
    return [FigureJob("probe", 1.0, lambda: json.dumps([loaded, kinds]).encode())]


out = {}
rep.start_renderer(processes=1).close()  # no helper: nothing imported for it
out["shared_none"] = "microg.structure.fem" in sys.modules
prober = rep.start_renderer(processes=2)  # started before the caller imports scipy, pydantic
out["shared_after"] = [type(sys.modules["numpy.ma"]).__name__,
                       all(m in sys.modules for m in rep.SHARED), "scipy" in sys.modules]
with rep.start_renderer(processes=2) as renderer:  # started before the computation
    out["active"] = renderer.active
    # the model's figures start once the modes are solved, the rest with the result
    result = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02,
                            on_modes=rep.early_figures(renderer))
    forked = rep.figures(result, renderer)
    out["error"] = renderer.error
    out["early_used"] = renderer.early_used
out["parent_loaded_matplotlib"] = "matplotlib" in sys.modules
here = rep.figures(result)
out["names"] = [list(forked), list(here)]
out["same_bytes"] = all(forked[k] == here[k] for k in here)
out["png"] = all(v[:8] == b"\x89PNG\r\n\x1a\n" for v in forked.values())


def failing(payload):
    raise RuntimeError("no figures today")


def one(payload):
    return [FigureJob("a.png", 1.0, lambda: b"a"), FigureJob("b.png", 1.0, lambda: b"b")]


def early(payload):
    return [FigureJob("a.png", 1.0, lambda: b"early a"), FigureJob("x.png", 1.0, lambda: b"x")]


def early_failing(payload):
    def fail():
        raise RuntimeError("no early figures")
    return [FigureJob("a.png", 1.0, fail)]


r = FigureRenderer.start((), processes=2)
r.draw_early(early, 1)
out["early"] = r.render(one, 1, reuse_early=True)  # a.png drawn early, x.png not asked
def pid_png():
    return str(os.getpid()).encode()


import tempfile
MARKS = tempfile.mkdtemp()


def started(mark):  # the early drawer has begun its figure (mark: a file name, or None)
    if mark:
        open(os.path.join(MARKS, mark), "w").close()


def wait_started(mark):  # until the early drawer has begun mark's figure (at most 60 s)
    deadline = time.monotonic() + 60
    while not os.path.exists(os.path.join(MARKS, mark)) and time.monotonic() < deadline:
        time.sleep(0.005)


def early_slow(mark):
    return [FigureJob("e.png", 1.0, lambda: started(mark) or time.sleep(0.1) or pid_png())]


def final_two(payload):
    slow = lambda: time.sleep(0.25) or pid_png()  # noqa: E731
    return [FigureJob(n, 1.0, slow) for n in ("e.png", "a.png", "b.png")]


r = FigureRenderer.start((), processes=2)
r.draw_early(early_slow, "shared")  # still drawing when the final request comes
wait_started("shared")
shared = r.render(final_two, 1, reuse_early=True)
out["early_shared"] = {k: int(v) for k, v in shared.items()} if shared else r.error


def early_busy(mark):
    return [FigureJob("e.png", 1.0, lambda: started(mark) or time.sleep(0.5) or pid_png())]


def final_quick(payload):
    return [FigureJob(n, 1.0, pid_png) for n in ("e.png", "a.png", "b.png")]


r = FigureRenderer.start((), processes=2)
r.draw_early(early_busy, None)  # busy until after the helper has drawn its share
shared = r.render(final_quick, 1, reuse_early=True)
out["early_busy"] = {k: int(v) for k, v in shared.items()} if shared else r.error


def stamp_png(sleep_s):
    return lambda: time.sleep(sleep_s) or f"{os.getpid()} {time.monotonic()}".encode()


def final_uneven(payload):
    # the same weight, not the same cost: a static share would give the helper two jobs
    jobs = [FigureJob("e.png", 1.0, stamp_png(0.1))]
    return jobs + [FigureJob(n, 1.0, stamp_png(s)) for n, s in (("a", 0.6), ("b", 0.05),
                                                                ("c", 0.05), ("d", 0.05))]


def final_weighted(payload):
    return [FigureJob(n, w, stamp_png(0.02)) for n, w in (("e.png", 1.0), ("a", 1.0),
                                                          ("b", 3.0), ("c", 2.0))]


r = FigureRenderer.start((), processes=2)
r.draw_early(early_slow, "uneven")
wait_started("uneven")
shared = r.render(final_uneven, 1, reuse_early=True)
out["early_uneven"] = {k: v.decode().split() for k, v in shared.items()} if shared else r.error
r = FigureRenderer.start((), processes=2)
r.draw_early(early_busy, "weighted")  # busy throughout: the helper draws a, b, c
wait_started("weighted")
shared = r.render(final_weighted, 1, reuse_early=True)
out["early_weighted"] = {k: v.decode().split() for k, v in shared.items()} if shared else r.error
def early_unwanted(mark):
    return [FigureJob("x.png", 1.0, lambda: started(mark) or time.sleep(1.5) or b"x")]


def early_hung(mark):
    return [FigureJob("a.png", 1.0, lambda: started(mark) or time.sleep(30) or b"late a")]


for reuse in (True, False):  # an early figure the reply does not use is not waited for
    r = FigureRenderer.start((), processes=2)
    r.draw_early(early_unwanted, f"unwanted{reuse}")
    wait_started(f"unwanted{reuse}")
    t = time.monotonic()
    got = r.render(one, 1, reuse_early=reuse)
    out[f"early_unwanted_{reuse}"] = [got and sorted(got), time.monotonic() - t]
import microg.report.render as render_module
render_module.DRAWER_TIMEOUT_S = 1.0
r = FigureRenderer.start((), processes=2)
r.draw_early(early_hung, "hung")  # a drawer that never answers is given up
wait_started("hung")
t = time.monotonic()
got = r.render(one, 1, reuse_early=True)
out["early_hung"] = [got and {k: v.decode() for k, v in got.items()}, time.monotonic() - t,
                     r.early_used]
render_module.DRAWER_TIMEOUT_S = render_module.TIMEOUT_S / 3
r = FigureRenderer.start((), processes=2)
r.draw_early(early, 1)
time.sleep(0.5)  # done before the final request comes
shared = r.render(final_two, 1)  # not reused: all are drawn again from the final request
out["early_not_reused"] = {k: int(v) for k, v in shared.items()} if shared else r.error
r = FigureRenderer.start((), processes=2)
r.draw_early(early_failing, 1)
out["early_failing"] = [r.render(one, 1, reuse_early=True), r.error]  # the final draws it
with rep.start_renderer(processes=2) as r:  # as microg analyze: early figures, then the page
    second = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02,
                            on_modes=rep.early_figures(r))
    files = rep.report_files(second, r)
    out["report_error"] = [r.error, r.early_used]
here_files = rep.report_files(second)
out["report_same"] = [list(files) == list(here_files),
                      all(files[k] == here_files[k] for k in here_files),
                      list(files)[-1]]
with rep.start_renderer(processes=2) as r:  # the early request of another analysis
    first = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02,
                           on_modes=rep.early_figures(r))
    other = microg.analyze("ioc", observe=["lab"], duration=40, dt=0.02, max_freq=2.0)
    stale = rep.figures(other, r)
    out["stale"] = [r.error, r.early_used, r.draw_early(rep.setup_jobs, first)]
fresh = rep.figures(other)
out["stale_same"] = [sorted(stale) == sorted(fresh), all(stale[k] == fresh[k] for k in fresh),
                     stale["modes.png"] != rep.figures(first)["modes.png"]]
with prober as r:
    probed = r.render(probe, result, omit=rep._unread(result.structure))
    out["probe"] = json.loads(probed["probe"]) if probed else r.error


def slow(payload):
    return [FigureJob("slow.png", 1.0, lambda: time.sleep(30) or b"late")]


def children_of(pid):
    kids = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    state, ppid = f.read().rsplit(")", 1)[1].split()[:2]
            except OSError:
                continue
            if int(ppid) == pid and state != "Z":
                kids.append(int(d))
    return kids


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


import time
r = FigureRenderer.start((), processes=2)
r.draw_early(slow, 1)  # the early drawer sleeps in its figure; then the caller fails
deadline, kids = time.monotonic() + 10, []
while not kids and time.monotonic() < deadline:
    time.sleep(0.01)
    kids = children_of(r._pid)
r.close()
time.sleep(0.2)
out["orphans"] = [len(kids), [k for k in kids if alive(k)]]
import microg.report.render as render_module
limit = render_module.MAX_PAYLOAD_BYTES
render_module.MAX_PAYLOAD_BYTES = 1000
r = FigureRenderer.start((), processes=2)
out["large_early"] = [r.draw_early(one, b"x" * 2000), r.render(one, 1), "MB" in (r.error or "")]
render_module.MAX_PAYLOAD_BYTES = limit
r = FigureRenderer.start((), processes=2)
out["failing"] = [r.render(failing, 1), "no figures today" in (r.error or "")]
r = FigureRenderer.start((), processes=2)
out["unpicklable"] = [r.render(one, lambda: 0), r.error is not None]
r = FigureRenderer.start((), processes=2)
os.kill(r._pid, 9)
out["killed"] = [r.render(one, 1), r.error is not None]
r = FigureRenderer.start((), processes=2)
out["tiny"] = r.render(one, 1)
import microg.report.render as render_module
render_module.MAX_PAYLOAD_BYTES = 1000
r = FigureRenderer.start((), processes=2)
out["large"] = [r.render(one, b"x" * 2000), "MB" in (r.error or ""), r.active]
calls = []
with rep.start_renderer(processes=2) as r:  # figures() runs while_waiting once on each path
    rep.figures(result, r, while_waiting=lambda: calls.append("helpers"))
    rep.figures(result, r, while_waiting=lambda: calls.append("closed"))
rep.figures(result, None, while_waiting=lambda: calls.append("none"))
out["while_waiting"] = calls
import time
r = FigureRenderer.start(rep.PRELOAD, processes=2)  # busy importing matplotlib
t = time.monotonic()
r.close()  # started and never used (an input error, say): the helper stops at once
out["close_s"] = time.monotonic() - t
out["closed"] = r.active
try:
    os.waitpid(-1, os.WNOHANG)
    out["children_left"] = True
except ChildProcessError:
    out["children_left"] = False
out["early"] = {k: v.decode() for k, v in out["early"].items()}
out["early_failing"][0] = {k: v.decode() for k, v in out["early_failing"][0].items()}
print(json.dumps({k: (v if not isinstance(v, dict) or k.startswith("early") else sorted(v))
                  for k, v in out.items()}, default=lambda b: b.decode()))
"""


@pytest.fixture(scope="module")
def forked() -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, check=True, timeout=300
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_helpers_draw_the_same_figures_as_the_caller(forked):
    assert forked["active"] and forked["error"] is None
    assert forked["names"][0] == forked["names"][1]  # same files, same (report) order
    assert forked["same_bytes"] and forked["png"]  # reference: in-process drawing, bytewise
    assert not forked["parent_loaded_matplotlib"]  # the caller never imported matplotlib


def test_early_figures_are_taken_by_name_and_drawn_once(forked):
    # a final job named as an early one takes the early figure; early-only names are dropped
    assert forked["early"] == {"a.png": "early a", "b.png": "b"}
    # an early drawer that fails costs nothing but time: the final request draws its jobs
    assert forked["early_failing"] == [{"a.png": "a", "b.png": "b"}, None]


def test_the_helper_writes_the_same_report_page(forked):
    # reference: the page and figures made in-process from the same result, byte for byte,
    # on microg analyze's path: the setup figures taken from the early request
    setup = ["forces.png", "model.png", "modes.png"]
    assert forked["report_error"] == [None, setup]
    assert forked["report_same"] == [True, True, "report.html"]
    assert forked["early_used"] == setup and forked["error"] is None


def test_the_early_drawer_takes_a_share_of_the_final_jobs(forked):
    # its own figure (0.1 s), then, free before the helper is done with its first final job
    # (0.25 s), the other one (drawn there: its pid).  Without reuse the early figure is
    # drawn again, by the helper or a fork
    pids = forked["early_shared"]
    assert pids["e.png"] in (pids["a.png"], pids["b.png"])  # the early drawer drew one
    assert pids["a.png"] != pids["b.png"]  # and the helper the other
    pids = forked["early_busy"]  # still busy when the helper is idle: it draws both
    assert pids["a.png"] == pids["b.png"] != pids["e.png"]
    pids = forked["early_not_reused"]
    assert sorted(pids) == ["a.png", "b.png", "e.png"] and len(set(pids.values())) == 2


def test_whoever_is_free_takes_the_next_job(forked):
    # the helper takes a (0.6 s); the early drawer, free after e (0.1 s), takes b, c and d
    # (0.05 s each) one after the other: the processes end near each other whatever the
    # weights said
    got = forked["early_uneven"]
    assert all(isinstance(v, list) for v in got.values()), got
    pid = {k: v[0] for k, v in got.items()}
    assert pid["b"] == pid["c"] == pid["d"] == pid["e.png"] != pid["a"]
    assert max(float(got[k][1]) for k in "bcd") < float(got["a"][1])


def test_the_heaviest_job_is_taken_first(forked):
    got = forked["early_weighted"]
    assert all(isinstance(v, list) for v in got.values()), got
    assert got["a"][0] == got["b"][0] == got["c"][0] != got["e.png"][0]  # the helper's
    order = sorted("abc", key=lambda k: float(got[k][1]))
    assert order == ["b", "c", "a"]  # weights 3, 2, 1


def test_the_reply_does_not_wait_for_an_early_figure_it_does_not_use(forked):
    # x.png (1.5 s) is not a final job; the final ones take no time
    for reuse in (True, False):
        names, seconds = forked[f"early_unwanted_{reuse}"]
        assert names == ["a.png", "b.png"] and seconds < 1.0, (reuse, seconds)


def test_a_drawer_that_never_answers_is_given_up(forked):
    # its early a.png sleeps 30 s; after DRAWER_TIMEOUT_S (1 s here) the helper draws the
    # final a.png itself and replies
    pngs, seconds, used = forked["early_hung"]
    assert pngs == {"a.png": "a", "b.png": "b"} and used == []
    assert 1.0 <= seconds < 10.0


def test_early_figures_of_another_analysis_are_not_used(forked):
    # an early request made from another run's modes: everything is drawn again, and the
    # files are the in-process ones of the result asked for (its modes.png differs)
    assert forked["stale"] == [None, [], False]  # and one early request per renderer
    assert forked["stale_same"] == [True, True, True]


def test_no_drawing_process_outlives_its_helper(forked):
    n, left = forked["orphans"]
    assert n == 1 and left == []  # the early drawer existed, and died with the helper


def test_a_large_early_request_is_refused_once(forked):
    # refused for its size; the final request is then not even tried (drawn in-process)
    assert forked["large_early"] == [False, None, True]


def test_what_both_processes_use_is_imported_once_before_the_fork(forked):
    # nothing for a renderer that starts no helper; with one, SHARED (numpy.ma run for
    # real, not a lazy stand-in) and still no scipy
    assert forked["shared_none"] is False
    assert forked["shared_after"] == ["module", True, False]


def test_the_helper_unpickles_an_analysis_without_scipy(forked):
    # neither scipy (the structure's sparse matrices are omitted stand-ins) nor pydantic
    assert forked["probe"] == [[], ["Modes", "Omitted"]]


def test_an_omitted_object_says_so_when_read():
    from microg.report.render import Omitted

    with pytest.raises(AttributeError, match="csr_matrix was omitted .*'toarray'"):
        Omitted("csr_matrix").toarray()


def test_a_failing_helper_means_drawing_in_process(forked):
    assert forked["failing"] == [None, True]  # None: the caller draws; the error is kept
    assert forked["unpicklable"] == [None, True]
    assert forked["killed"] == [None, True]


def test_a_large_result_is_drawn_in_process(forked):
    # a request above MAX_PAYLOAD_BYTES (a large model's mode shapes) is not sent
    assert forked["large"] == [None, True, False]


def test_the_callers_work_runs_once_on_every_path(forked):
    assert forked["while_waiting"] == ["helpers", "closed", "none"]


def test_helpers_share_the_jobs_and_stop(forked):
    assert forked["tiny"] == ["a.png", "b.png"]  # two jobs, one in each process, in order
    assert forked["closed"] is False
    assert forked["close_s"] < 0.5  # not waiting for the helper's imports (~0.5-1 s)
    assert forked["children_left"] is False  # every helper reaped


def test_one_process_starts_no_helper(monkeypatch):
    monkeypatch.setenv("MICROG_FIGURE_PROCESSES", "1")
    assert default_processes() == 1
    r = FigureRenderer.start(())
    assert not r.active and r.render(lambda p: [], None) is None
    monkeypatch.setenv("MICROG_FIGURE_PROCESSES", "not a number")
    assert default_processes() == 1


_NAMES = st.sampled_from("abcdefgh")
_JOBS = st.lists(st.tuples(_NAMES, st.floats(0.1, 5.0)), max_size=6, unique_by=lambda t: t[0])


@given(_JOBS, _JOBS.filter(bool), st.booleans(), st.integers(0, 6), st.integers(1, 3))
def test_the_queue_draws_each_final_figure_once_heaviest_first(early, final, reuse, ahead, n):
    # reference: the request's own list of jobs.  ``ahead`` early jobs are taken before the
    # final request comes, then ``n`` processes take turns until nothing is left
    q = _Queue([FigureJob(name, w, bytes) for name, w in early])
    drawn = [q.take(1) for _ in range(min(ahead, len(early)))]
    q.set_final([FigureJob(name, w, bytes) for name, w in final], b"", reuse)
    after = []
    while (job := q.take(len(after) % n)) is not None:
        after.append(job)
    weights = [q.jobs[k][i].weight for k, i in after]
    assert weights == sorted(weights, reverse=True)  # the heaviest first
    # every final figure exactly once: drawn from the final request, or (reuse) early
    got = [q.jobs["final"][i].name for k, i in after if k == "final"]
    if reuse:
        got += [q.jobs["early"][i].name for k, i in drawn + after if k == "early"]
        got = [name for name in got if name in dict(final)]
    else:
        assert all(k == "final" for k, _ in after)  # no early figure is drawn any more
    assert sorted(got) == sorted(dict(final))
    assert all(q.wanted(job) == (job[0] == "final" or reuse) for job in after)


DECK = r"""
import json, pickle, sys
import microg
import microg.report.analysis as rep
deck = sys.argv[1]
with rep.start_renderer(processes=2) as r:
    model = microg.load_model(deck, units="m,N,s")
    res = microg.analyze(model, at="grid:11", observe=["grid:6"], duration=20, dt=0.01,
                         on_modes=rep.early_figures(r))
    files = rep.report_files(res, r)
    out = {"error": r.error, "early_used": r.early_used}
here = rep.report_files(res)
out["same"] = [list(files) == list(here), all(files[k] == here[k] for k in here)]
back = pickle.loads(pickle.dumps(res.structure))
a, b = res.structure.point("grid:3"), back.point("grid:3")  # a node map built on demand
out["node_map"] = [bool((a.translation == b.translation).all()),
                   bool((a.rotation == b.rotation).all())]
print(json.dumps(out))
"""


def test_a_nastran_decks_figures_are_drawn_by_the_helper_too():
    # a frame (graph) model's structure pickles (its node maps are an object, not a
    # closure), so the helper draws its figures; reference: the in-process files, bytewise
    from pathlib import Path

    deck = Path(__file__).resolve().parents[3] / "shared/fixtures/nastran/beam_modes/beam_modes.dat"
    if not deck.is_file():
        pytest.skip("the NASTRAN fixture (../shared) is not beside the repository")
    proc = subprocess.run(
        [sys.executable, "-c", DECK, str(deck)],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["error"] is None and out["early_used"]  # the helper drew, early ones too
    assert out["same"] == [True, True]
    assert out["node_map"] == [True, True]  # the same point map after a pickle round trip
