"""The one scheduler of ``tslip reproduce``: each task once, largest first, dependencies kept;
a parallel reproduction equals a serial one bit for bit; an interrupted one resumes."""

import dataclasses
import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tslip.sweeps import _schedule, catalogue
from tslip.sweeps import run as run_mod
from tslip.sweeps._schedule import Task, choose_workers, run_tasks
from tslip.sweeps.run import saved_points

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


def _record(folder: str, key: str, value: int, tick=None) -> int:
    """A task: leaves one line in ``folder/key`` per run (any process), returns value**2."""
    with open(os.path.join(folder, key), "a") as f:
        f.write(f"{os.getpid()}\n")
    return value * value


def _chain_tasks(folder: Path, n: int = 6) -> tuple[list[Task], dict]:
    """Roots ``r0..r{n-1}``; each root's result makes a child ``c<i>`` ready."""
    roots = [Task(f"r{i}", _record, (str(folder), f"r{i}", i), cost=float(i)) for i in range(n)]
    got: dict[str, int] = {}

    def on_done(task, result):
        assert task.key not in got  # delivered once
        got[task.key] = result
        if task.key.startswith("r"):
            i = int(task.key[1:])
            return [Task(f"c{i}", _record, (str(folder), f"c{i}", result + 1), cost=0.5)]
        return []

    return roots, got, on_done


@pytest.mark.parametrize("workers", [1, 2])
def test_every_task_runs_exactly_once_and_its_children_see_its_result(tmp_path, workers):
    roots, got, on_done = _chain_tasks(tmp_path)
    timing: dict = {}
    run_tasks(roots, on_done, workers=workers, timing=timing)
    n = len(roots)
    expected = {**{f"r{i}": i * i for i in range(n)}, **{f"c{i}": (i * i + 1) ** 2
                                                          for i in range(n)}}
    assert got == expected
    runs = {f.name: f.read_text().splitlines() for f in tmp_path.iterdir()}
    assert {k: len(v) for k, v in runs.items()} == dict.fromkeys(expected, 1)
    if workers == 2:  # ran in worker processes, not here
        assert all(int(v[0]) != os.getpid() for v in runs.values())
    # timing: each task once, children made ready by their root
    assert set(timing) == set(expected)
    assert all(timing[f"c{i}"][2] == f"r{i}" and timing[f"r{i}"][2] is None for i in range(n))
    assert all(cpu >= 0 and wall >= 0 for cpu, wall, _ in timing.values())


def test_serial_order_is_largest_first_among_the_ready(tmp_path):
    order: list[str] = []
    tasks = [Task(k, _record, (str(tmp_path), k, 1), cost=c)
             for k, c in (("small", 1.0), ("large", 9.0), ("mid", 4.0))]

    def on_done(task, result):
        order.append(task.key)
        if task.key == "large":  # a task made ready later, larger than those waiting
            return [Task("urgent", _record, (str(tmp_path), "urgent", 1), cost=2.0,
                         priority=20.0)]
        return []

    run_tasks(tasks, on_done, workers=1)
    assert order == ["large", "urgent", "mid", "small"]


def test_a_failing_task_stops_the_run_and_raises(tmp_path):
    tasks = [Task("bad", _record, (str(tmp_path / "missing"), "bad", 1))]
    for workers in (1, 2):
        with pytest.raises(FileNotFoundError):
            run_tasks(tasks, lambda t, r: [], workers=workers)


def test_worker_count_follows_the_work_unless_given(monkeypatch):
    s = _schedule.STARTUP_SECONDS
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    assert choose_workers(0.5 * s) == 1  # start-up would dominate: serial
    assert choose_workers(7.9 * s) == 1  # less than 4 start-ups of work per worker
    assert choose_workers(8.1 * s) == 2
    assert choose_workers(1000 * s) == 2  # all cores, no more
    assert choose_workers(1000 * s, width=1) == 1  # one task at a time
    assert choose_workers(0.5 * s, 3) == 3  # the caller's choice
    assert choose_workers(1000 * s, 1) == 1
    with pytest.raises(ValueError, match="workers must be >= 1"):
        choose_workers(10.0, 0)


# --- the whole reproduction at the tiny resolution --------------------------------------


def _same(a, b, path="data") -> None:
    """Exact equality of nested results (NaN equals NaN; arrays element by element)."""
    if isinstance(a, run_mod.StudyResult):
        pd.testing.assert_frame_equal(a.frame.drop(columns="seconds"),
                                      b.frame.drop(columns="seconds"), check_exact=True)
        return
    assert type(a) is type(b), path
    if isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            _same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, Sequence) and not isinstance(a, str):  # lists, Trajectory.steps
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b, err_msg=path)
    elif isinstance(a, float):
        assert a == b or (math.isnan(a) and math.isnan(b)), path
    elif dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif hasattr(a, "__dict__") and not isinstance(a, type):
        _same(vars(a), vars(b), path)
    else:
        assert a == b, path


def _claims(claims):
    return [(c.figure, c.text, c.verdict, repr(c.numbers)) for c in claims]


@pytest.fixture(scope="module")
def serial_tiny(tmp_path_factory):
    """The tiny reproduction, serial: data, claims, its wall seconds, what it reported."""
    from tslip.sweeps.reproduce import run_all

    out = tmp_path_factory.mktemp("serial")
    reported: list[tuple[str, str, float]] = []
    data, claims, seconds = run_all(out, resolution="tiny", workers=1,
                                    progress=lambda *args: reported.append(args))
    return data, claims, seconds, reported


def test_each_study_and_figure_reports_its_own_time(serial_tiny):
    """Run one after the other, the studies' and figures' own times add up to at most the
    run's wall time; times counted from the start of the run would add up to many times it."""
    data, _, wall, reported = serial_tiny
    studies = {name: s for stage, name, s in reported if stage == "study"}
    assert set(studies) == set(catalogue.studies("tiny"))
    assert all(s == data[name].meta["seconds"] > 0 for name, s in studies.items())
    assert sum(s for _, _, s in reported) <= wall


def test_two_interleaved_studies_report_their_own_time(monkeypatch):
    """A fake clock on which a task takes one second per point: a 1-point study and a
    4-point one, their tasks interleaved on one run, report 2 s and 8 s (a solve and an
    analysis per point), which add up to the run's 10 s (counted from the start of the
    run, each would report up to 10 s)."""
    from tslip.model.parameters import preset
    from tslip.sweeps import Axis, StudySpec

    clock = [0.0]
    fake = type("FakeTime", (), {"perf_counter": staticmethod(lambda: clock[0]),
                                 "process_time": staticmethod(lambda: clock[0])})
    monkeypatch.setattr(_schedule, "time", fake)

    def costing(real, points):
        def task(*args):
            clock[0] += len(args[points])
            return real(*args)
        return task

    monkeypatch.setattr(run_mod, "_solve_task", costing(run_mod._solve_task, 2))
    monkeypatch.setattr(run_mod, "_analyse_task", costing(run_mod._analyse_task, 1))
    base = preset("table2.1")
    jobs = {name: run_mod.StudyJob(StudySpec(name, base, axes=(Axis("k", values),),
                                             analyses=("floquet",)), None)
            for name, values in (("one", (20.0,)), ("four", (18.0, 19.0, 20.0, 21.0)))}

    def on_done(task, result):
        return jobs[task.key[0]].on_done(task, result)

    timing: dict = {}
    run_tasks([t for j in jobs.values() for t in j.start()], on_done, 1, timing=timing)
    # own time: the tasks' seconds, and (real seconds) the keys made and the cache read here
    own = {name: j.result(1, timing=timing).meta["seconds"] - j.load_seconds
           for name, j in jobs.items()}
    assert own == pytest.approx({"one": 2.0, "four": 8.0})
    assert clock[0] == 10.0


def test_parallel_reproduction_equals_serial_bit_for_bit(serial_tiny, tmp_path):
    from tslip.sweeps.reproduce import run_all

    timing: dict = {}
    info: dict = {}
    data, claims, _ = run_all(tmp_path, resolution="tiny", workers=2, timing=timing, info=info)
    assert info == {"workers": 2}  # named in the report's header
    _same(serial_tiny[0], data)
    assert _claims(serial_tiny[1]) == _claims(claims)
    # every line solved once, every point computed once and cached
    specs = catalogue.studies("tiny")
    solves = [k for k in timing if k[1] == "solve"]
    assert sorted(solves) == sorted((n, "solve", i) for n, s in specs.items()
                                    for i in range(len(s.lines())))
    for name, spec in specs.items():
        assert data[name].meta["computed"] == spec.n_points
        assert data[name].meta["workers"] == 2
        assert saved_points(spec, tmp_path / "studies" / name) == spec.n_points
    assert {k[2] for k in timing if k[:2] == ("figure", "E")} >= {"e2_floquet",
                                                                  "converged_floquet"}


def test_pieces_land_under_their_own_names(serial_tiny):
    """Table 6.1's variants and Appendix E's perturbed starts, each against a direct call."""
    from tslip.biped import BipedParams, simulate
    from tslip.gait import find_gait
    from tslip.gait.robustness import robustness
    from tslip.model.parameters import preset
    from tslip.sweeps.appendix_e import table_e2_perturbations
    from tslip.sweeps.reproduce import APPENDIX_E_SETTINGS

    data = serial_tiny[0]
    g = find_gait(preset("table6.1"))
    variants = data["table6.1"]["pitch_rate_variants"]
    assert variants["apex, +"] == robustness(g, "pitch_rate", sign=1, placement="apex",
                                             check=False)
    assert variants["liftoff, -"] == robustness(g, "pitch_rate", sign=-1, placement="liftoff",
                                                check=False)
    e2 = data["E"]["e2"]
    st = APPENDIX_E_SETTINGS["tiny"]
    starts = table_e2_perturbations(st["n_random"], one_at_a_time=st["one_at_a_time"])
    assert e2["strides_perturbed"] == [
        simulate(BipedParams(), y, st["n_strides"]).count_strides(e2["min_contact"])
        for y in starts]


def test_interrupted_reproduction_resumes_to_the_same_result(serial_tiny, tmp_path,
                                                              monkeypatch):
    from tslip.sweeps.reproduce import run_all

    real, saves, k = run_mod._save, [], 7

    def interrupting(cache, key, rec):
        real(cache, key, rec)
        saves.append(key)
        if len(saves) == k:
            raise KeyboardInterrupt

    monkeypatch.setattr(run_mod, "_save", interrupting)
    with pytest.raises(KeyboardInterrupt):
        run_all(tmp_path, resolution="tiny", workers=1)
    monkeypatch.setattr(run_mod, "_save", real)
    specs = catalogue.studies("tiny")
    saved = sum(saved_points(s, tmp_path / "studies" / n) for n, s in specs.items())
    assert saved == k
    locks = list(tmp_path.glob("studies/*/.lock"))
    assert len(locks) == len(specs) and all(f.read_text() == "" for f in locks)  # released
    data, claims, _ = run_all(tmp_path, resolution="tiny", workers=2)
    assert sum(data[n].meta["cached"] for n in specs) == k
    assert sum(data[n].meta["computed"] for n in specs) == sum(s.n_points
                                                               for s in specs.values()) - k
    _same(serial_tiny[0], data)
    assert _claims(serial_tiny[1]) == _claims(claims)
