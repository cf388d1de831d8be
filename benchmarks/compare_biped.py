"""Bit-for-bit comparison of the biped kernels' outputs between two checkouts.

Run by hand (not in CI), once per checkout, each with its own ``src`` first on the
path and its own numba cache, then compare::

    PYTHONPATH=/work/main/src NUMBA_CACHE_DIR=/tmp/a python benchmarks/compare_biped.py dump a.npz
    PYTHONPATH=src NUMBA_CACHE_DIR=/tmp/b python benchmarks/compare_biped.py dump b.npz
    python benchmarks/compare_biped.py compare a.npz b.npz

``dump`` runs the biped from three starts (the Table E.2 start of ``BipedParams()``
and the two stored gaits, ``converged-e2`` and ``optimised``), each also pushed,
pitched and pushed until it falls, with both Runge-Kutta pairs at two tolerances
(1e-8 and 1e-11): ``simulate`` over a few strides (the recorded trajectory, the
event log, the stride log, the final state, contact state and counts), a run cut
at ``t_end`` and resumed from its final contact state (the step-down path),
``step`` and ``step_map``; then, at the stored gaits, ``disturbed_outcome`` of each
disturbance, ``section_multipliers`` and ``floquet`` (both pairs) and a short
``find_periodic_gait``. ``compare`` reports every array whose bits differ (exit
status 1 if any). Only API that every checkout since the biped's ``step`` rename
has is used.
"""
from __future__ import annotations

import sys

import numpy as np

_KINDS = ("touchdown_R", "touchdown_L", "liftoff_R", "liftoff_L", "fall")


def _traj(res: dict, key: str, tr, pk) -> None:  # noqa: ANN001 - Trajectory, _pack
    """The arrays of a Trajectory under ``key/...``."""
    res[f"{key}/data"] = tr.data
    res[f"{key}/events"] = np.array([[e.t, e.foot_x, e.foot_z] for e in tr.events]
                                    ).reshape(-1, 3)
    res[f"{key}/event_kinds"] = np.array([_KINDS.index(e.kind) for e in tr.events],
                                         dtype=np.int64)
    res[f"{key}/strides"] = tr.strides
    res[f"{key}/end"] = np.r_[tr.final_state, tr.final_contact, int(tr.status),
                              tr.stats["accepted"], tr.stats["rejected"],
                              tr.stats["rhs_calls"], tr.stats["t_end"]]


def _starts():  # noqa: ANN202
    """``{name: (params, y, t0, z or None)}``: the thesis start and the stored gaits."""
    from tslip.biped import BipedParams, BipedState
    from tslip.biped.gait import to_section
    from tslip.biped.stored import STORED_GAITS, load_gait

    out = {"thesis": (BipedParams(), BipedState.thesis().to_array(), 0.0, None)}
    for name in STORED_GAITS:
        p, y, t0, _ = load_gait(name)
        out[name] = (p, y, t0, to_section(p, y, t0))
    return out


def _kinds(y: np.ndarray) -> dict[str, np.ndarray]:
    """The start itself and disturbed copies (a push, a pitch rate, a push that falls)."""
    push, pitch, fall = y.copy(), y.copy(), y.copy()
    push[9] += 0.05
    pitch[11] += 0.1
    pitch[14] -= 0.1
    pitch[17] -= 0.1
    fall[9] += 1.0
    return {"plain": y, "push": push, "pitch": pitch, "fall": fall}


def _runs(res: dict, pk) -> None:  # noqa: ANN001 - the _pack module
    """simulate / step / step_map of every start, disturbance, pair and tolerance."""
    from tslip.biped import BipedOptions, simulate, step
    from tslip.biped.gait import step_map, to_section

    for sn, (p, y0, t0, _) in _starts().items():
        for kn_, y in _kinds(y0).items():
            for m in ("dopri5", "dop853"):
                for tol in (1e-8, 1e-11):
                    o = BipedOptions(rtol=tol, atol=tol, method=m)
                    key = f"{sn}/{kn_}/{m}/{tol:g}"
                    _traj(res, f"sim/{key}", simulate(p, y, 3, t0=t0, options=o), pk)
                    r = step(p, y, t0, options=o)
                    res[f"step/{key}"] = np.r_[int(r.status), r.t, r.state, r.contact,
                                               r.accepted]
                    z1, st = step_map(p, to_section(p, y, t0), options=o)
                    res[f"map/{key}"] = np.r_[z1, int(st)]
                    if kn_ != "plain":
                        continue
                    # cut in the first stride and resumed from the cut's contact state
                    part = simulate(p, y, 1, t0=t0, t_end=t0 + 0.4, options=o)
                    _traj(res, f"cut/{key}", part, pk)
                    y1 = part.final_state.copy()
                    y1[1] -= 0.01
                    rest = simulate(p, y1, 2, t0=float(part.stats["t_end"]),
                                    contact=part.final_contact, options=o)
                    _traj(res, f"resumed/{key}", rest, pk)


def _gaits(res: dict) -> None:
    """Disturbed outcomes, multipliers and a short search at the stored gaits."""
    from tslip.biped import BipedOptions
    from tslip.biped.gait import (
        DISTURBANCES,
        disturbed_outcome,
        find_periodic_gait,
        floquet,
        section_multipliers,
    )

    for sn, (p, _, _, z) in _starts().items():
        if z is None:
            continue
        for kind in DISTURBANCES:
            for value in (-0.02, -0.3):
                st, done = disturbed_outcome(p, z, kind, value, 4)
                res[f"disturbed/{sn}/{kind}/{value:g}"] = np.r_[-1 if st is None else int(st),
                                                                done]
        for m in ("dopri5", "dop853"):
            o = BipedOptions(rtol=1e-11, atol=1e-11, max_steps=200_000,
                             stride_time_max=3.0, method=m)
            res[f"multipliers/{sn}/{m}"] = section_multipliers(p, z, options=o)
            fl = floquet(p, z, options=o)
            res[f"floquet/{sn}/{m}"] = np.r_[fl.multipliers, fl.jacobian.ravel(), fl.residual]
        g = find_periodic_gait(p, z, cma_evals=30, lsq_evals=20,
                               options=BipedOptions(method="dopri5"))
        res[f"search/{sn}"] = np.r_[g.z, g.residual, int(g.converged)]


def dump(path: str) -> None:
    from tslip.biped import _pack as pk

    res: dict[str, np.ndarray] = {}
    _runs(res, pk)
    _gaits(res)
    np.savez(path, **{k: np.asarray(v) for k, v in res.items()})
    print(f"{len(res)} arrays written to {path}")


def compare(a: str, b: str) -> int:
    A, B = np.load(a), np.load(b)
    bad = 0
    if set(A.files) != set(B.files):
        print("key sets differ", set(A.files) ^ set(B.files))
        bad += 1
    for k in sorted(set(A.files) & set(B.files)):
        x, y = A[k], B[k]
        if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
            bad += 1
            if x.shape != y.shape or x.dtype != y.dtype:
                print("DIFF", k, x.shape, x.dtype, y.shape, y.dtype)
                continue
            both = np.isnan(x) & np.isnan(y)
            d = np.where(both, 0.0, np.abs(x - y))
            print(f"DIFF {k} {x.shape}: {int((d != 0).sum())} values, largest {np.nanmax(d):.2e}")
    print(f"{len(A.files)} arrays compared, {bad} differ")
    return bad


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(sys.argv[2])
    elif sys.argv[1] == "compare":
        sys.exit(1 if compare(sys.argv[2], sys.argv[3]) else 0)
    else:
        sys.exit(f"usage: {sys.argv[0]} dump OUT.npz | compare A.npz B.npz")
