"""The study runner: serial == parallel, resume, cache invalidation, spec validation."""

import dataclasses

import pandas as pd
import pytest

import tslip
from tslip.sweeps import Axis, StudySpec, run_study
from tslip.sweeps import run as run_mod


def _spec(**kw):
    base = dict(name="grid", base=tslip.preset("table2.1-local-velocity"),
                axes=(Axis("v0", (4.0, 5.0)), Axis("k", (20.0, 25.0))), analyses=("floquet",))
    base.update(kw)
    return StudySpec(**base)


def _cmp(a: pd.DataFrame, b: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(a.drop(columns="seconds"), b.drop(columns="seconds"))


def test_two_by_two_serial_equals_parallel(tmp_path):
    spec = _spec(analyses=("floquet", "robustness"))
    serial = run_study(spec, tmp_path / "s", workers=1)
    parallel = run_study(spec, tmp_path / "p", workers=2)
    assert serial.meta["computed"] == parallel.meta["computed"] == 4
    assert serial.frame["converged"].all()
    _cmp(serial.frame, parallel.frame)


def test_cache_invalidated_by_parameter_and_code(tmp_path, monkeypatch):
    spec = _spec()
    run_study(spec, tmp_path, workers=1)
    changed = _spec(base=dataclasses.replace(tslip.preset("table2.1-local-velocity"), J=0.12))
    assert run_study(changed, tmp_path, workers=1).meta["computed"] == 4
    assert run_study(spec, tmp_path, workers=1).meta["computed"] == 0
    monkeypatch.setattr(run_mod, "code_version", lambda analyses: "edited")
    assert run_study(spec, tmp_path, workers=1).meta["computed"] == 4


def test_missing_gait_is_recorded_not_raised(tmp_path):
    spec = StudySpec("low-speed", tslip.preset("table2.1"), (Axis("v0", (1.0, 5.0)),))
    res = run_study(spec, None, workers=1)
    df = res.frame.set_index("v0")
    assert not df.loc[1.0, "converged"] and df.loc[1.0, "stability"] == "none"
    assert df.loc[5.0, "converged"]
    # the multiplier columns: none without a gait; with one, Floquet's magnitudes, descending
    mags = [f"abs_lambda_{j}" for j in range(1, 6)]
    assert df.loc[1.0, mags + ["max_nontrivial", "min_nontrivial"]].isna().all()
    assert df.loc[1.0, "n_trivial"] == 0
    fl = tslip.floquet(tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"), v0=5.0)))
    ref = sorted(abs(fl.multipliers), reverse=True)
    assert df.loc[5.0, mags].to_numpy(float) == pytest.approx(ref, abs=1e-8)
    assert df.loc[5.0, "n_trivial"] == fl.trivial.sum() > 0  # the energy's at least (passive)
    nontrivial = abs(fl.multipliers[~fl.trivial])
    assert df.loc[5.0, "max_nontrivial"] == pytest.approx(nontrivial.max(), abs=1e-8)
    assert df.loc[5.0, "min_nontrivial"] == pytest.approx(nontrivial.min(), abs=1e-8)


@pytest.mark.parametrize(
    ("toml", "needle"),
    [('[[axis]]\nparam = "stiffness"\nfrom = 1\nto = 2\npoints = 3\n', "stiffness"),
     ('[[axis]]\nparam = "r"\nfrom = 1\nto = 1\npoints = 3\n', "empty range"),
     ('[[axis]]\nparam = "r"\nvalues = []\n', "empty range"),
     ('[[axis]]\nparam = "k"\nfrom = -5\nto = 20\npoints = 3\n', "k ["),
     ('[params]\nk = -3\n[[axis]]\nparam = "r"\nfrom = 0\nto = 1\npoints = 3\n', "k ["),
     ('analyses = ["magic"]\n[[axis]]\nparam = "r"\nvalues = [0.1]\n', "magic"),
     ('colour = 1\n[[axis]]\nparam = "r"\nvalues = [0.1]\n', "colour"),
     ('tol = 0.5\n[[axis]]\nparam = "r"\nvalues = [0.1]\n', "tol must be a number in"),
     ('neutral_tol = "1e-6"\n[[axis]]\nparam = "r"\nvalues = [0.1]\n', "neutral_tol")],
)
def test_bad_spec_rejected_with_one_line(tmp_path, toml, needle):
    f = tmp_path / "s.toml"
    f.write_text(toml)
    with pytest.raises(ValueError) as exc:
        StudySpec.from_toml(f)
    msg = str(exc.value)
    assert needle in msg and "\n" not in msg


def test_toml_roundtrip(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('name = "r-sweep"\npreset = "table2.1"\nanalyses = ["floquet", "stride"]\n'
                 '[params]\nk = 30\n[[axis]]\nparam = "r"\nfrom = 0.1\nto = 0.5\npoints = 5\n')
    spec = StudySpec.from_toml(f)
    assert spec.base.k == 30.0 and spec.shape == (5,) and spec.axes[0].values[-1] == 0.5
    assert StudySpec.from_dict(spec.to_dict()) == spec


def test_toml_tolerances_reach_the_run_and_its_cache_key(tmp_path):
    """``tol`` and ``neutral_tol`` in a study's TOML: kept, used, and part of the cache key."""
    f = tmp_path / "s.toml"
    f.write_text('name = "tols"\ntol = 1e-7\nneutral_tol = 1e-4\n'
                 '[[axis]]\nparam = "r"\nvalues = [0.2, 0.3]\n')
    spec = StudySpec.from_toml(f)
    assert spec.meta == {"tol": 1e-7, "neutral_tol": 1e-4}
    assert StudySpec.from_dict(spec.to_dict()).meta == spec.meta
    res = run_study(spec, tmp_path / "out", workers=1)
    assert res.meta["tol"] == 1e-7 and res.meta["study"]["neutral_tol"] == 1e-4
    assert (res.frame["residual"] <= 1e-7).all()
    # the default tolerance is another study: nothing of the first is reused
    plain = StudySpec.from_dict({k: v for k, v in spec.to_dict().items()
                                 if k not in ("tol", "neutral_tol")})
    assert plain.meta == {}
    assert run_study(plain, tmp_path / "out", workers=1).meta["computed"] == 2
    assert run_study(spec, tmp_path / "out", workers=1).meta["computed"] == 0


def test_dask_cluster_gives_the_same_results(tmp_path):
    """--scheduler ADDRESS: the same lines on a Dask cluster (here a local one)."""
    from dask.distributed import Client, LocalCluster

    spec = _spec()
    serial = run_study(spec, tmp_path / "s", workers=1)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster):
        dask = run_study(spec, tmp_path / "d", scheduler=cluster.scheduler_address)
    assert dask.meta["scheduler"] == cluster.scheduler_address
    _cmp(serial.frame, dask.frame)


def _double(x, tick=None):
    return 2 * x


def test_a_dask_cluster_gets_a_bounded_number_of_tasks_at_a_time(monkeypatch):
    """Submitting every task at once held each one's arguments and result in this process
    (4 GB for a 4500-chunk viability map): at most DASK_IN_FLIGHT per worker thread are
    out, and every task still runs once."""
    from dask.distributed import Client, LocalCluster

    from tslip.sweeps import _schedule

    out = {"now": 0, "max": 0}
    submit = Client.submit

    def counting(self, *args, **kwargs):
        out["now"] += 1
        out["max"] = max(out["max"], out["now"])
        return submit(self, *args, **kwargs)

    done = []

    def on_done(task, result):
        out["now"] -= 1
        done.append(result)
        return []

    monkeypatch.setattr(Client, "submit", counting)
    tasks = [_schedule.Task(("t", i), _double, (i,)) for i in range(30)]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        _schedule.run_tasks(tasks, on_done, scheduler=cluster.scheduler_address)
    assert sorted(done) == [2 * i for i in range(30)]
    assert out["max"] == _schedule.DASK_IN_FLIGHT


@pytest.mark.parametrize("address, what", [
    ("foo", "--scheduler 'foo' is not a Dask scheduler's address (ValueError: missing port"),
    ("http://127.0.0.1:1", "--scheduler 'http://127.0.0.1:1' is not a Dask scheduler's "
                           "address (ValueError: unknown address scheme 'http'"),
])
def test_the_api_refuses_a_bad_scheduler_before_building_a_client(monkeypatch, address, what):
    """run_tasks(scheduler=...) checks the address itself (not only the CLI), before a
    ``Client`` is built: a Client whose constructor failed hung CI for 900 s when
    collected."""
    from dask.distributed import Client

    from tslip.sweeps import _schedule

    def no_client(*args, **kwargs):
        raise AssertionError("a Client was built for a bad address")

    monkeypatch.setattr(Client, "__init__", no_client)
    with pytest.raises(ValueError) as err:
        _schedule.run_tasks([_schedule.Task(("t", 0), _double, (0,))], lambda t, r: [],
                            scheduler=address)
    assert what in str(err.value) and "\n" not in str(err.value)


def test_the_scheduler_check_works_inside_a_running_event_loop():
    """The check runs its connection on a loop of its own: called where a loop already
    runs (a notebook, or a test that left one running) it still judges the address,
    instead of failing with asyncio's "cannot be called from a running event loop"."""
    import asyncio
    import threading

    from tslip.sweeps._schedule import check_scheduler

    async def main():
        with pytest.raises(ValueError) as err:
            check_scheduler("foo", 0.5)
        return str(err.value)

    said = []  # this test's loop runs in a thread of its own: the suite's main thread may
    # hold a loop left running by an earlier test, where asyncio.run refuses to start one
    thread = threading.Thread(target=lambda: said.append(asyncio.run(main())))
    thread.start()
    thread.join(30)
    assert said and said[0].startswith(
        "--scheduler 'foo' is not a Dask scheduler's address (ValueError: missing port")


def test_the_scheduler_check_works_in_a_thread_that_holds_a_running_loop():
    """As the suite's main thread was left by an earlier test: a loop marked running here
    (asyncio's own marker, restored after) does not stop the check judging the address."""
    import asyncio

    from tslip.sweeps._schedule import check_scheduler

    previous = asyncio.events._get_running_loop()
    loop = asyncio.new_event_loop()
    asyncio.events._set_running_loop(loop)
    try:
        with pytest.raises(ValueError, match=r"^--scheduler 'foo' is not a Dask scheduler's "
                                             r"address \(ValueError: missing port"):
            check_scheduler("foo", 0.5)
    finally:
        asyncio.events._set_running_loop(previous)
        loop.close()
