"""What the lean paths of step_map and simulate keep: a packed Params never goes stale, and
a trajectory's table, derived on first read, is the same whichever way it is read."""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np

import tslip
from tslip.model import _pack as pk
from tslip.simulation.result import TRAJECTORY_COLUMNS

P = tslip.preset("table6.1")
Q = np.array([0.93, 0.0, 1.9 * np.cos(0.3), -1.9 * np.sin(0.3), 0.0])


def test_the_packed_parameters_follow_each_instance():
    """The vector kept on a Params is that Params' own: a replaced copy (another k) maps
    as a Params built from scratch with that k does, not as the one it came from."""
    pk.packed_params(P)  # cached on P
    stiffer = dataclasses.replace(P, k=9.0)
    assert pk.packed_params(stiffer)[pk.P_K] == 9.0
    fresh = tslip.Params(**{**P.to_dict(), "k": 9.0,
                            "controller": P.controller})
    a, b = tslip.step_map(stiffer, Q), tslip.step_map(fresh, Q)
    assert np.array_equal(a.q, b.q) and a.stance_time == b.stance_time
    assert not np.array_equal(a.q, tslip.step_map(P, Q).q)  # k matters to this stride


def test_the_cache_is_invisible_to_equality_hashing_and_pickling():
    p = tslip.preset("table6.1")
    pk.packed_params(p)
    q = pickle.loads(pickle.dumps(p))
    assert q == p and hash(q) == hash(p) and repr(q) == repr(p)
    assert "_packed" not in dataclasses.asdict(p)
    assert np.array_equal(pk.packed_params(q), pk.pack_params(p))


def test_step_map_reads_the_state_and_height_it_is_given():
    """A section as a list and as an array, and the ground height, against step()."""
    h = -0.05
    r = tslip.step_map(P, Q.tolist(), h=h)
    td = tslip.TouchdownState(*Q, x=0.0, h=h)
    ref = tslip.step(P, td, terrain=tslip.Terrain.flat(h))
    assert r.status == ref.status == tslip.Status.OK
    assert np.array_equal(r.q, ref.state.section())
    assert type(r.stance_time) is float and r.stance_time == ref.stance_time


def test_the_table_is_the_same_before_and_after_data_is_read():
    g = tslip.find_gait(P)
    lazy = tslip.simulate(g.params, g.state, 4)
    read = tslip.simulate(g.params, g.state, 4)
    data = read.data  # derived now; lazy's frame derives its own
    a, b = lazy.to_dataframe(), read.to_dataframe()
    assert a.equals(b) and list(a.columns) == list(TRAJECTORY_COLUMNS)
    for j, name in enumerate(TRAJECTORY_COLUMNS):
        assert np.array_equal(a[name].to_numpy(dtype=float), data[:, j]), name
    assert a["step"].dtype == np.int64 and a["stance"].dtype == bool


def test_a_frame_owns_its_memory():
    """Writing into the frame leaves the trajectory as it was (and the other way round)."""
    g = tslip.find_gait(P)
    tr = tslip.simulate(g.params, g.state, 3)
    before = tr.data.copy()
    df = tr.to_dataframe()
    df.loc[0, "x"] = 123.0
    df.loc[1, "t"] = 456.0
    assert np.array_equal(tr.data, before)
    tr.data[2, TRAJECTORY_COLUMNS.index("y")] = 789.0
    assert df.loc[2, "y"] != 789.0
