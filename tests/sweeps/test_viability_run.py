"""``run_viability`` over three apex variables: a Dask cluster gives the worker pool's
bytes, a run resumes on either, the spec's ``[actions.<name>]`` form, and the chunk
store reads data only (issue 28)."""

import io
import json

import numpy as np
import pytest

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
                       (ACTIONS + "\n[actions.k]\nvalues = [20.0]", "one \\[actions.<name>\\]"),
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
