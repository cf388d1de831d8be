"""Processes: no worker outlives a killed parent; Ctrl-C ends quietly with a resume line;
one writer per study folder."""

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest

import tslip
from tslip.sweeps import Axis, StudySpec, run_study
from tslip.sweeps._lock import FolderLocked, folder_lock, folder_locks
from tslip.sweeps.run import saved_points

# a 2-D study of 5 lines of 13 points: the line at the base value v0 = 5 first, then
# two continuation chains (v0 = 4.5; v0 = 5.5, 6, 6.5) in two workers, one soon idle
# Robustness over 100 strides makes each point about 0.3 s (one worker, load 4; 0.58 s over
# 200 strides, 0.14 s over 50): the study must still be running when the tests below signal
# it (with Floquet alone, 65 points take 0.2 s), and the sigkill test runs it twice more.
_TOML = """name = "grid"
preset = "table2.1-local-velocity"
analyses = ["floquet", "robustness"]
n_steps = 100
[[axis]]
param = "v0"
values = [4.5, 5.0, 5.5, 6.0, 6.5]
[[axis]]
param = "k"
from = 20.0
to = 26.0
points = 13
"""

_SCRIPT = """
import sys
from tslip.sweeps import StudySpec, run_study
run_study(StudySpec.from_toml(sys.argv[1]), sys.argv[2], workers=2)
"""


def _sigint_default() -> None:
    """Ctrl-C as in a terminal, for a child: a shell starts background jobs with
    SIGINT ignored, and a child inherits that (Python then installs no handler)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def ctrl_c_raises():
    """This process raises KeyboardInterrupt on SIGINT, even if started with it ignored."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def _env():
    src = str(Path(tslip.__file__).parents[1])
    return {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _wait_for(cond, timeout=240.0):
    t0 = time.monotonic()
    while not cond():
        if time.monotonic() - t0 > timeout:
            raise TimeoutError
        time.sleep(0.1)


def _n_cached(out: Path) -> int:
    """Points saved in the study's cache file (a line torn by the kill not counted)."""
    return saved_points(StudySpec.from_toml(out.parent / "grid.toml"), out)


def _wait_gone(procs, seconds=10.0):
    """The processes still alive after up to ``seconds`` (the resource tracker ends last)."""
    deadline = time.monotonic() + seconds
    while _alive(procs) and time.monotonic() < deadline:
        time.sleep(0.1)
    return _alive(procs)


def _alive(procs):
    out = []
    for p in procs:
        try:
            if p.status() != psutil.STATUS_ZOMBIE:
                out.append(p)
        except psutil.NoSuchProcess:
            pass
    return out


def test_sigkill_of_the_parent_ends_its_workers_and_the_study_resumes(tmp_path):
    spec_file = tmp_path / "grid.toml"
    spec_file.write_text(_TOML)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-c", _SCRIPT, str(spec_file), str(out)],
                            env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parent = psutil.Process(proc.pid)
    try:  # the root line (13 points) is done and both chains are running
        _wait_for(lambda: _n_cached(out) >= 15 and len(parent.children(recursive=True)) >= 2)
        children = parent.children(recursive=True)
    finally:
        proc.kill()
        proc.wait()
    assert len(children) >= 2
    assert not _wait_gone(children)
    # the points the killed run saved are reused, and the result is exactly the full run's
    spec = StudySpec.from_toml(spec_file)
    saved = _n_cached(out)
    resumed = run_study(spec, out, workers=1)
    assert resumed.meta["cached"] == saved and 15 <= saved < spec.n_points
    full = run_study(spec, tmp_path / "full", workers=1)
    pd.testing.assert_frame_equal(full.frame.drop(columns="seconds"),
                                  resumed.frame.drop(columns="seconds"), check_exact=True)


def test_ctrl_c_prints_one_resume_line_and_exits_130(tmp_path):
    spec_file = tmp_path / "grid.toml"
    spec_file.write_text(_TOML)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "tslip.cli", "study", str(spec_file),
                             "--out", str(out), "--workers", "2"], env=_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_sigint_default)
    try:  # the first two lines are done: one worker is busy, the other idle
        _wait_for(lambda: _n_cached(out) >= 28)
        children = psutil.Process(proc.pid).children(recursive=True)
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal does: the whole process group
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "leaked" not in err  # the terminated workers left no named semaphore behind
    m = re.search(r"^(\d+) of 65 points saved; rerun the same command to resume$", err,
                  re.MULTILINE)
    assert m, err
    assert int(m.group(1)) == _n_cached(out) >= 28
    assert not _wait_gone(children)


def test_second_run_on_a_locked_folder_is_refused_in_one_line(tmp_path):
    spec = StudySpec("one", tslip.preset("table2.1"), (Axis("v0", (5.0,)),))
    with folder_lock(tmp_path):
        with pytest.raises(FolderLocked) as exc:
            run_study(spec, tmp_path, workers=1)
    msg = str(exc.value)
    assert str(tmp_path) in msg and f"pid {os.getpid()}" in msg and "\n" not in msg
    assert not (tmp_path / "cache").exists()  # it computed nothing
    run_study(spec, tmp_path, workers=1)  # released: the folder is free again


def test_lock_of_a_killed_run_is_stale_and_taken_over(tmp_path, caplog):
    code = ("import os, sys\nfrom tslip.sweeps._lock import folder_lock\n"
            "with folder_lock(sys.argv[1]):\n    os.kill(os.getpid(), 9)\n")
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path)], env=_env(),
                          timeout=60)
    assert proc.returncode == -9
    dead = int(re.search(r'"pid": (\d+)', (tmp_path / ".lock").read_text()).group(1))
    with caplog.at_level("WARNING", logger="tslip"), folder_lock(tmp_path):
        pass
    assert [f"pid {dead}" in r.getMessage() and "stale" in r.getMessage()
            for r in caplog.records] == [True]
    with caplog.at_level("WARNING", logger="tslip"), folder_lock(tmp_path):
        pass  # released cleanly last time: nothing to report
    assert len(caplog.records) == 1


def test_the_stale_locks_of_a_killed_run_of_many_studies_are_one_line(tmp_path, caplog):
    folders = [tmp_path / "studies" / f"s{i}" for i in range(18)]
    # every reading of the clock a second later than the last: a run that takes a second to
    # lock its folders is one holder, with one start time
    code = ("import itertools, os, sys, time\nfrom tslip.sweeps._lock import folder_locks\n"
            "tick, fmt = itertools.count(), time.strftime\n"
            "time.strftime = lambda f, *a: fmt(f, time.localtime(1e9 + next(tick)))\n"
            "with folder_locks(sys.argv[1:]):\n    os.kill(os.getpid(), 9)\n")
    proc = subprocess.run([sys.executable, "-c", code, *map(str, folders)], env=_env(),
                          timeout=60)
    assert proc.returncode == -9
    dead = int(re.search(r'"pid": (\d+)', (folders[-1] / ".lock").read_text()).group(1))
    with caplog.at_level("WARNING", logger="tslip"), folder_locks(folders):
        pass
    msgs = [r.getMessage() for r in caplog.records]
    assert len(msgs) == 1, msgs
    assert msgs[0].startswith(f"taking over the stale locks on 18 folders under "
                              f"{tmp_path / 'studies'} from pid {dead} on "), msgs[0]
    assert len(re.findall(r"pid \d+", msgs[0])) == 1  # one holder, named once


def test_idle_workers_ignore_sigint_and_the_parent_stops_them():
    from tslip.sweeps._pool import process_pool

    with process_pool(2) as pool:
        assert list(pool.map(abs, [-1, -2])) == [1, 2]
        workers = list(pool._processes.values())
        for w in workers:  # Ctrl-C reaches the whole process group, idle workers included
            os.kill(w.pid, signal.SIGINT)
        time.sleep(1.0)
        assert all(w.is_alive() for w in workers)
        assert pool.submit(abs, -3).result(timeout=60) == 3
        with pytest.raises(KeyboardInterrupt):  # the parent's Ctrl-C
            with process_pool(2) as inner:
                inner.submit(time.sleep, 60)
                inner_workers = list(inner._processes.values())
                raise KeyboardInterrupt
    assert not any(w.is_alive() for w in inner_workers)  # stopped, not waited for


def test_wait_blocks_until_the_holder_releases(tmp_path, caplog):
    import threading

    got = threading.Event()

    def second():
        with folder_lock(tmp_path, wait=True):
            got.set()

    with caplog.at_level("WARNING", logger="tslip"):
        with folder_lock(tmp_path):
            t = threading.Thread(target=second)
            t.start()
            _wait_for(lambda: any("waiting for" in r.getMessage() for r in caplog.records),
                      timeout=30)
            assert not got.is_set()  # still held here
        t.join(timeout=30)
    assert got.is_set()
    assert f"pid {os.getpid()}" in caplog.records[0].getMessage()


def test_ctrl_c_during_the_final_wait_stops_the_workers(ctrl_c_raises):
    """Leaving the block starts a wait for the workers (one still busy here, as a slow
    starter would be); a Ctrl-C during it stops them instead of leaving them running."""
    import threading

    from tslip.sweeps._pool import process_pool

    ctrl_c = threading.Timer(3.0, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        with process_pool(2) as pool:
            pool.submit(time.sleep, 120)
            workers = list(pool._processes.values())
            ctrl_c.start()
    assert time.monotonic() - t0 < 60  # not waited for
    assert workers and not any(w.is_alive() for w in workers)
