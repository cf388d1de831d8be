"""``run_viability`` over three apex variables: a Dask cluster gives the worker pool's
bytes, a run resumes on either, the spec's ``[actions.<name>]`` form, and the chunk
store reads data only (issue 28)."""

import dataclasses
import io
import json
import tracemalloc

import numpy as np
import pytest

import tslip
from tslip.gait import _viable
from tslip.gait._viable import RULES
from tslip.gait.viability import StateActionMap, StoredMap, state_action_map, viability
from tslip.sweeps import viability as sv

SPEC = """
name = "tiny3"
preset = "slip"
energy = 2.6

[[state]]
name = "y"
from = 0.9
to = 2.2
points = 6

[[state]]
name = "phi"
values = [-0.2, 0.0, 0.2]

[[state]]
name = "phid"
values = [-0.1, 0.0, 0.1]

{action}
"""
ACTION = "[action]\nname = \"alpha_r\"\nfrom = 1.05\nto = 1.4\npoints = 4"
ACTIONS = "[actions.alpha_r]\nvalues = [1.05, 1.1666666666666667, 1.2833333333333332, 1.4]"
N = 6 * 3 * 3 * 4


@pytest.fixture
def spec(tmp_path, monkeypatch):
    monkeypatch.setattr(sv, "CHUNK_CELLS", 40)  # 54 states x 4 actions, chunks of 10 states
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.format(action=ACTION))
    return sv.ViabilitySpec.from_toml(path)


def _same(a, b) -> None:
    assert a.map.next.tobytes() == b.map.next.tobytes()
    assert np.array_equal(a.map.status, b.map.status)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.s, b.s) and a.sweeps == b.sweeps


def test_spec_over_three_variables_and_the_actions_table(spec, tmp_path):
    assert spec.shape == (6, 3, 3, 4) and len(spec.chunks()) == 6
    path = tmp_path / "b.toml"
    path.write_text(SPEC.format(action=ACTIONS))
    other = sv.ViabilitySpec.from_toml(path)
    assert other.action == spec.action and sv.chunk_keys(other) == sv.chunk_keys(spec)
    for bad, match in ((ACTION + "\n" + ACTIONS, "one of the two"),
                       (ACTIONS + "\n[actions.k]\nvalues = [20.0]\n[actions.c_l]\nvalues = [0.0]",
                        "one or two \\[actions.<name>\\]"),
                       ("", "one of the two")):
        path.write_text(SPEC.format(action=bad))
        with pytest.raises(ValueError, match=match) as exc:
            sv.ViabilitySpec.from_toml(path)
        assert "\n" not in str(exc.value)


def test_dask_local_cluster_gives_the_worker_pools_result(spec, tmp_path):
    from dask.distributed import Client, LocalCluster

    pool = sv.run_viability(spec, tmp_path / "pool", workers=2)
    assert pool.map.names == ("y", "phi", "phid") and pool.q.any() and (~pool.q).any()
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster):
        address = cluster.scheduler_address
        dask = sv.run_viability(spec, tmp_path / "dask", scheduler=address)
        _same(pool, dask)
        for f in (tmp_path / "pool" / "cache").glob("*.npz"):
            assert (tmp_path / "dask" / "cache" / f.name).read_bytes() == f.read_bytes()
        assert ((tmp_path / "pool" / "results.parquet").read_bytes()
                == (tmp_path / "dask" / "results.parquet").read_bytes())
        meta = json.loads((tmp_path / "dask" / "run.json").read_text())
        assert meta["scheduler"] == address and meta["computed"] == N
        # an interrupted run (two chunks lost) resumes on the cluster, and on the pool
        lost = sorted((tmp_path / "dask" / "cache").glob("*.npz"))[:2]
        for f in lost:
            f.unlink()
        again = sv.run_viability(spec, tmp_path / "dask", scheduler=address)
    _same(pool, again)
    meta = json.loads((tmp_path / "dask" / "run.json").read_text())
    assert 0 < meta["computed"] < N and meta["cached"] == N - meta["computed"]
    lost[0].unlink()
    _same(pool, sv.run_viability(spec, tmp_path / "dask", workers=1))


def test_the_chunk_store_reads_data_only(spec, tmp_path):
    ref = sv.run_viability(spec, tmp_path / "ref", workers=1)
    files = sorted((tmp_path / "ref" / "cache").glob("*.npz"))
    good = files[0]
    with np.load(good) as z:
        nxt, status = z["next"], z["status"]
    n = len(nxt)
    got = sv.read_chunk(good, n, 4, 3)
    assert got is not None and got[0].tobytes() == nxt.tobytes()
    assert sv.read_chunk(good, n, 4, 2) is None  # another shape

    def write(path, **arrays):
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        path.write_bytes(buf.getvalue())

    bad = {
        "pickle": {"next": np.array([object()] * 3, dtype=object), "status": status},
        "float32": {"next": nxt.astype(np.float32), "status": status},
        "text status": {"next": nxt, "status": status.astype(str)},
        "extra": {"next": nxt, "status": status, "more": status},
    }
    for name, arrays in bad.items():
        write(good, **arrays)
        assert sv.read_chunk(good, n, 4, 3) is None, name
    good.write_bytes(b"PK\x03\x04 damaged")
    assert sv.read_chunk(good, n, 4, 3) is None
    with np.load(files[1]) as z:
        n1 = len(z["status"])
    write(files[1], next=np.array([object()] * 3, dtype=object), status=status)
    again = sv.run_viability(spec, tmp_path / "ref", workers=1)  # both computed again
    _same(ref, again)
    assert json.loads((tmp_path / "ref" / "run.json").read_text())["computed"] == (n + n1) * 4


SLIP = """
name = "slip1"
preset = "slip"
energy = 2.6

[[state]]
name = "y"
from = 0.9
to = 2.2
points = {n}

[action]
name = "alpha_r"
from = 1.05
to = 1.4
points = 20
"""


def _slip(tmp_path, n, rule="bracket"):
    path = tmp_path / f"slip{n}.toml"
    path.write_text(SLIP.format(n=n))
    return dataclasses.replace(sv.ViabilitySpec.from_toml(path), rule=rule)


@pytest.mark.parametrize("rule", RULES)
def test_a_stored_run_equals_the_in_memory_map(spec, tmp_path, rule):
    """With an output folder the result's map is the chunk store, read on demand; the map,
    the viable sets and the saved table equal the in-memory ``state_action_map`` and
    ``viability`` of the same grid (the iteration never saw the store's floats at once)."""
    spec = dataclasses.replace(spec, rule=rule)
    res = sv.run_viability(spec, tmp_path / "run", workers=1)
    assert isinstance(res.map, StoredMap) and res.map.folder == tmp_path / "run" / "cache"
    ref = viability(state_action_map(spec.base, {a.param: a.values for a in spec.states},
                                     spec.actions(), energy=spec.energy,
                                     options=spec.options), rule)
    _same(ref, res)
    assert np.array_equal(res.map.failed, ref.map.failed)
    back = tslip.load(tmp_path / "run" / "results.parquet")
    assert isinstance(back.map, StateActionMap)
    _same(ref, back)
    assert back.map.params == ref.map.params and back.rule == rule


def test_peak_memory_of_a_stored_run_does_not_grow_with_the_map(tmp_path, monkeypatch):
    """tracemalloc's peak (numpy's arrays included) over a stored run of 4,000 and of
    16,000 cells: the larger map adds less than 3 bytes a cell, the viable pairs (one byte
    each) and the bookkeeping of its chunks; holding the float map (24 bytes a cell with
    its status), its int32 cells (8) or its table (over 40) would add many times that."""
    monkeypatch.setattr(sv, "CHUNK_CELLS", 400)
    monkeypatch.setattr(_viable, "CHUNK_ROWS", 1000)
    peaks = {}
    for n in (200, 800):  # x 20 actions
        spec = _slip(tmp_path, n)
        sv.run_viability(spec, tmp_path / f"warm{n}", workers=1)  # compiled, cached, imported
        tracemalloc.start()
        res = sv.run_viability(spec, tmp_path / f"run{n}", workers=1)
        peaks[n] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert res.q.size == 20 * n and res.q.any() and (~res.q).any()
    grown = peaks[800] - peaks[200]
    assert grown < 3 * 20 * 600, (peaks, grown / (20 * 600))


def test_a_spec_with_two_actions(tmp_path):
    """Two ``[actions.<name>]`` tables: the run's map has the two action axes in the order
    written and equals the in-memory two-action map; the cache keys differ from either
    action alone."""
    two = "[actions.alpha_r]\nvalues = [1.1, 1.2, 1.3]\n[actions.k]\nvalues = [20.0, 30.0]\n"
    path = tmp_path / "two.toml"
    path.write_text(SLIP.format(n=12).split("[action]")[0] + two)
    spec = sv.ViabilitySpec.from_toml(path)
    assert spec.shape == (12, 3, 2) and [a.param for a in spec.action_axes] == ["alpha_r", "k"]
    res = sv.run_viability(spec, tmp_path / "run", workers=1)
    assert res.map.action == ("alpha_r", "k") and res.q.shape == (12, 3, 2)
    ref = viability(state_action_map(spec.base, {"y": spec.states[0].values},
                                     {"alpha_r": [1.1, 1.2, 1.3], "k": [20.0, 30.0]},
                                     energy=spec.energy, options=spec.options))
    _same(ref, res)
    assert sv.ViabilitySpec.from_dict(spec.to_dict()).action == spec.action
    path.write_text(SLIP.format(n=12).split("[action]")[0] + two.split("[actions.k]")[0])
    assert not set(sv.chunk_keys(sv.ViabilitySpec.from_toml(path))) & set(sv.chunk_keys(spec))
