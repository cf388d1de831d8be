"""The first run: it says which kernel families it compiles, and compiles each once."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tslip import _kernel_cache as kc

_ANNOUNCE = textwrap.dedent("""
    import json, sys, time
    from tslip.sweeps._warmup import announce, cache_dirs
    print(json.dumps({k: str(v) for k, v in cache_dirs().items()}), flush=True)
    if sys.argv[1] == "fabricate":
        sys.exit(0)
    with announce(lambda s: print("SAID " + s, flush=True)) as missing:
        pass
""")


def _run(cache: Path, mode: str) -> list[str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", _ANNOUNCE, mode], env=env, text=True,
                         capture_output=True, timeout=120, check=True).stdout
    return out.splitlines()


def test_a_cold_cache_is_announced_and_a_warm_one_is_not(tmp_path):
    cold = _run(tmp_path, "announce")
    said = [s for s in cold if s.startswith("SAID ")]
    planar = {k: v for k, v in kc.FAMILIES.items() if v[0] in ("simulation", "biped")}
    assert len(said) == 1 and f"compiling {len(planar)} kernel families" in said[0]
    for name in kc.FAMILIES:
        assert (name in said[0]) == (name in planar)  # the 3-D ones: only for 3-D studies
    # the same folders, as a warm cache (index files of every family's kernels)
    dirs = {k: Path(v) for k, v in json.loads(_run(tmp_path, "fabricate")[0]).items()}
    for package, kernels in planar.values():
        dirs[package].mkdir(parents=True, exist_ok=True)
        for kernel in kernels:
            stem = kernel.split(".")[0]
            (dirs[package] / f"{stem}.tslip-sources").write_text(kc.sources_hash())
            (dirs[package] / f"{kernel}-12.py311.nbi").write_text("x")
    warm = _run(tmp_path, "announce")
    assert not [s for s in warm if s.startswith("SAID ")]


_RECORDER = textwrap.dedent("""
    import os
    from numba.core import event

    class _Log(event.Listener):
        def on_start(self, e):
            pass

        def on_end(self, e):
            d = e.data["dispatcher"]
            with open(os.environ["TSLIP_TEST_COMPILE_LOG"], "a") as f:
                f.write(f"{os.getpid()}\\t{d.py_func.__module__}.{d.py_func.__qualname__}"
                        f"\\t{e.data['args']}\\n")

    event.register("numba:compile", _Log())
""")

_RUN = textwrap.dedent("""
    import sys
    import tslip.simulation  # noqa: F401 - the fork server warms the TSLIP's families
    from tslip.sweeps._schedule import Task, run_tasks

    def gait(name, tick):
        from tslip.sweeps import catalogue
        return catalogue._gait(name).converged

    if __name__ == "__main__":
        tasks = [Task(("a",), gait, ("table2.1",)), Task(("b",), gait, ("table6.1",))]
        if sys.argv[1] == "split":  # as tslip reproduce: the recorded runs compile here
            from tslip.sweeps._warmup import warm_in_background
            warm = warm_in_background(("TSLIP recorded runs",))
        run_tasks(tasks, lambda task, result: [], workers=2, preload=sys.argv[2:])
        if sys.argv[1] == "split":
            warm.join()
            print("MAIN", __import__("os").getpid())
""")


@pytest.mark.slow
def test_no_kernel_is_compiled_in_two_processes(tmp_path):
    """Two gait searches at once on 2 workers from an empty cache, as a study's pool runs
    them, while this process warms the recorded runs (as ``tslip reproduce`` does): every
    kernel signature compiles in one process (the strides' and the gait search's in the
    fork server, the recorded runs' here, after the strides are cached, while the fork
    server compiles the gait search).

    Without ``tslip.sweeps._prewarm`` in the preload, both workers compile the
    stride kernels at the same moment; without the wait for the strides
    (``_warmup.NEEDS``), this process compiles them too; with a recorded runs' workload
    that searches its gaits (``catalogue._gait``), this process compiles the gait
    search's Jacobian kernel too (the break checks).
    """
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(_RECORDER)  # runs in every process (fork server too)
    (tmp_path / "run.py").write_text(_RUN)
    log = tmp_path / "compiles.tsv"
    src = str(Path(kc.__file__).parents[1])
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "TSLIP_TEST_COMPILE_LOG": str(log),
           "PYTHONPATH": os.pathsep.join([str(site), src])}
    out = subprocess.run([sys.executable, str(tmp_path / "run.py"), "split",
                          "tslip.sweeps._prewarm"], env=env, check=True, timeout=1800,
                         cwd=tmp_path, capture_output=True, text=True).stdout
    main = out.split("MAIN ")[1].strip()
    where: dict[tuple[str, str], set[str]] = {}
    for line in log.read_text().splitlines():
        pid, fn, args = line.split("\t")
        where.setdefault((fn, args), set()).add(pid)
    by_fn = {fn: pids for (fn, _), pids in where.items()}
    # the compiling was split: the gait search in the fork server, the recorded runs here
    assert by_fn["tslip.simulation._stride.stride"] - {main}
    assert by_fn["tslip.simulation._record.record_run"] == {main}
    # numba's own overloads (np.empty, int, ...) compile in every process that compiles
    # anything and are never cached: only the package's kernels count
    twice = {k: v for k, v in where.items() if len(v) > 1 and k[0].startswith("tslip.")}
    assert not twice, twice


def test_the_stored_gaits_are_gaits_of_their_presets():
    """The recorded runs' workload runs from stored gaits instead of searching them (so it
    needs none of the gait search's kernels): each is its preset but the unknowns the
    search solves, and one stride maps its touch-down state to itself (Section 2.8's
    periodicity; the search stopped at a residual below 1e-12, integrating to 1e-12 as
    here)."""
    import dataclasses

    import numpy as np

    import tslip
    from tslip.sweeps._warmup import STORED_GAITS, stored_gait

    assert set(STORED_GAITS) == {"table2.1", "table6.1"}  # the figures' and Table 6.1's
    for name in STORED_GAITS:
        g = stored_gait(name)
        base = tslip.preset(name)
        assert dataclasses.replace(g.params, alpha_r=base.alpha_r,
                                   controller=base.controller) == base
        q = g.state.section()
        res = tslip.step_map(g.params, q, options=tslip.IntegratorOptions.tight("dop853"))
        assert res.status == tslip.Status.OK
        assert np.max(np.abs(res.q - q)) < 1e-11, name


def test_study_and_reproduce_pools_warm_their_kernels_before_forking(monkeypatch, tmp_path):
    """The wiring: both pools' fork servers import ``_prewarm``, last (after the task modules)."""
    from tslip.sweeps import _pool, catalogue, reproduce, run

    seen = {}

    class Stop(Exception):
        pass

    def run_tasks(*args, preload=(), **kwargs):
        seen["study"] = list(preload)
        raise Stop

    def prestart(preload):
        seen["reproduce"] = list(preload)
        raise Stop

    monkeypatch.setattr(run, "run_tasks", run_tasks)
    with pytest.raises(Stop):
        run.run_study(catalogue.study("leg_damping", "tiny"), workers=2)
    assert seen["study"] == ["tslip.sweeps._prewarm"]
    monkeypatch.setattr(_pool, "prestart", prestart)
    monkeypatch.setattr(reproduce, "warm_in_background", lambda: seen.setdefault("main", seen))
    with pytest.raises(Stop):
        reproduce.run_catalogue(tmp_path, "tiny", workers=2)
    assert seen["reproduce"][-1] == "tslip.sweeps._prewarm"
    assert "main" in seen  # its own families claimed before the fork server starts


_BIPED_WARM = textwrap.dedent("""
    import json
    from numba.core import event
    from tslip import _kernel_cache as kc
    from tslip.biped import BipedOptions, BipedParams, BipedState, simulate
    from tslip.biped.dynamics import body_positions, controller_references, momentum
    from tslip.sweeps._warmup import WORKLOADS, cache_dirs

    WORKLOADS["biped"]()
    missing = kc.missing_families(cache_dirs(("biped",)), kc.sources_hash())
    compiled = []

    class _Log(event.Listener):
        def on_start(self, e):
            pass

        def on_end(self, e):
            compiled.append(e.data["dispatcher"].py_func.__qualname__)

    event.register("numba:compile", _Log())
    p, s = BipedParams(), BipedState.thesis()
    momentum(p, s)
    controller_references(p, 0.25)
    body_positions(p, s)
    simulate(p, s, 1, options=BipedOptions(method="dop853"))  # the other pair, same loop
    print(json.dumps({"missing": missing, "compiled": compiled}))
""")


@pytest.mark.slow
def test_the_biped_warm_up_compiles_what_appendix_e_calls_from_python(tmp_path):
    """After the biped family's workload (a dopri5 stride), its family is cached, and
    neither the helpers Appendix E's tasks call from Python (momentum, body positions,
    controller references) nor a dop853 stride (the loop takes the pair at run time)
    compile anything more: a worker running those tasks after the fork compiles nothing."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _BIPED_WARM], env=env, text=True,
                         capture_output=True, timeout=1200, check=True).stdout
    got = json.loads(out.splitlines()[-1])
    assert "biped" not in got["missing"]
    assert got["compiled"] == []


@pytest.fixture
def claims(monkeypatch, tmp_path):
    """Claims as lock files in ``tmp_path``, and a fake family whose workload is logged."""
    from tslip.sweeps import _warmup

    monkeypatch.setattr(_warmup, "_claim_path", lambda name: tmp_path / f"{name}.lock")
    state = {"missing": True, "runs": []}
    monkeypatch.setitem(_warmup.WORKLOADS, "fake", lambda: state["runs"].append(1))
    monkeypatch.setattr(_warmup, "_is_missing", lambda name: state["missing"])
    return _warmup, state


def test_a_claim_held_elsewhere_is_seen_and_waited_for(claims):
    import threading

    warmup, state = claims
    held, release, order = threading.Event(), threading.Event(), []

    def holder():
        with warmup.claim("fake") as ok:
            assert ok
            held.set()
            release.wait(10)
            order.append("holder done")
            state["missing"] = False  # the holder cached it

    t = threading.Thread(target=holder)
    t.start()
    held.wait(10)
    with warmup.claim("fake", wait=False) as ok:  # a second open file: the lock is busy
        assert not ok
    assert warmup.warm(["fake"], wait=False) == ["fake"] and state["runs"] == []
    threading.Timer(0.3, release.set).start()
    warmup.ensure(("fake",))  # waits for the holder, then finds it cached: runs nothing
    order.append("ensure done")
    t.join()
    assert order == ["holder done", "ensure done"] and state["runs"] == []
    with warmup.claim("fake", wait=False) as ok:  # released
        assert ok


def test_ensure_warms_a_family_nobody_warms_once(claims):
    warmup, state = claims

    def workload():
        state["runs"].append(1)
        state["missing"] = False

    warmup.WORKLOADS["fake"] = workload
    warmup.ensure(("fake",))
    warmup.ensure(("fake",))
    assert state["runs"] == [1]


def test_a_link_at_the_claim_file_is_not_followed(claims, tmp_path):
    warmup, _ = claims
    target = tmp_path / "elsewhere" / "created.txt"  # a link may point anywhere
    target.parent.mkdir()
    (tmp_path / "fake.lock").symlink_to(target)
    with warmup.claim("fake") as ok:
        assert ok  # unclaimed, as when the folder cannot be written
    assert not target.exists()


_RUN_3D = textwrap.dedent("""
    import os
    from tslip.sweeps.run import run_study
    from tslip.sweeps.spec import StudySpec

    if __name__ == "__main__":
        spec = StudySpec.from_dict({
            "name": "s3", "model": "slip3d", "analyses": ["floquet"], "params": {},
            "axis": [{"param": "k", "values": [18.0, 20.0]},
                     {"param": "k_lat", "values": [0.0, 1.0]}]})
        res = run_study(spec, None, workers=2)
        print("MAIN", os.getpid(), len(res.frame))
""")


@pytest.mark.slow
def test_a_3d_study_compiles_its_kernels_once_before_its_workers(tmp_path):
    """A 3-D study on 2 workers from an empty cache (two independent lines, one a worker):
    its model's kernels compile in this process only, before the pool; the workers load
    them. Without the ``ensure`` in ``run._run``, both workers compile the 3-D stance."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(_RECORDER)
    (tmp_path / "run.py").write_text(_RUN_3D)
    log = tmp_path / "compiles.tsv"
    src = str(Path(kc.__file__).parents[1])
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "TSLIP_TEST_COMPILE_LOG": str(log),
           "PYTHONPATH": os.pathsep.join([str(site), src])}
    out = subprocess.run([sys.executable, str(tmp_path / "run.py")], env=env, check=True,
                         timeout=1200, cwd=tmp_path, capture_output=True, text=True).stdout
    main, rows = out.split("MAIN ")[1].split()
    assert int(rows) == 4
    where: dict[str, set[str]] = {}
    for line in log.read_text().splitlines():
        pid, fn, _ = line.split("\t")
        if fn.startswith("tslip."):
            where.setdefault(fn, set()).add(pid)
    assert where["tslip.spatial._kernels.stance"] == {main}
    assert all(pids == {main} for pids in where.values()), where
