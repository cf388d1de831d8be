"""Bit-for-bit comparison of the TSLIP kernels' outputs between two checkouts.

Run by hand (not in CI), once per checkout, each with its own ``src`` first on the
path and its own numba cache, then compare::

    PYTHONPATH=/work/main/src NUMBA_CACHE_DIR=/tmp/a python benchmarks/compare_kernels.py dump a.npz
    PYTHONPATH=src NUMBA_CACHE_DIR=/tmp/b python benchmarks/compare_kernels.py dump b.npz
    python benchmarks/compare_kernels.py compare a.npz b.npz

``dump`` runs every preset (and a soft-leg and an apex-clock variant) from four
touch-down states (one falls) with both integrator methods at three tolerances:
``step_map``, ``step_jacobian``, ``step``, the packed map and Jacobian, ``simulate``
(with and without a disturbance), the recorded stance alone, serial and parallel
batches on step terrain, and ``find_gait`` with its Floquet multipliers (1408
arrays). ``compare`` reports every array whose bits differ (exit status 1 if any).
A stride's output vector is saved without the slots a checkout added after
another (``_OUT_ADDED``, e.g. the leg thrust's ``OUT_TSW``), so checkouts on either
side of that change compare. Likewise a recorded stance is saved in the layout of the
first checkouts, ``t, y, F_x, F_y, tau`` a row: where the kernel records ``t, y`` alone
(no ``REC_FX``), the forces are derived from them as ``StepResult.grf`` derives them.
"""
import sys

import numpy as np

_OUT_ADDED = ("OUT_TSW",)  # output slots added since the first checkouts compared


def _old_out(out: np.ndarray, pk) -> np.ndarray:  # noqa: ANN001 - the _pack module
    """``out`` (or rows of it) without the slots of :data:`_OUT_ADDED` this checkout has."""
    drop = [getattr(pk, name) for name in _OUT_ADDED if hasattr(pk, name)]
    return np.delete(out, drop, axis=-1)


def _old_rec(rows: np.ndarray, P: np.ndarray, at_steps: bool, pk) -> np.ndarray:  # noqa: ANN001
    """Stance record ``rows`` as ``t, y, F_x, F_y, tau``: the forces derived if this checkout
    records ``t, y`` only (no leg thrust here: the stance alone reports no switch)."""
    if hasattr(pk, "REC_FX"):
        return rows
    from tslip.simulation._record import stance_forces

    assert P[pk.P_THRUST] == 0.0, "a thrust's switch time is not known here"
    grf = np.empty((len(rows), 4))
    stance_forces(P, np.ascontiguousarray(rows), np.nan, at_steps, grf)
    return np.column_stack((rows, grf[:, 1:]))


def dump(path: str) -> None:
    import dataclasses

    import tslip
    from tslip.model import _pack as pk
    from tslip.model.parameters import presets
    from tslip.simulation import _kernels as kn
    from tslip.simulation import _packed

    res = {}
    states = {
        "s1": (1.05, 0.0, 5.0, -0.3, 0.0),
        "s2": (0.95, 0.03, 1.8, -0.45, 0.1),
        "s3": (1.2, -0.05, 3.0, -0.8, -0.2),
        "slow": (1.3, 0.0, 0.6, -0.2, 0.0),  # falls
    }
    opts = {
        "d5": tslip.IntegratorOptions(),
        "d853": tslip.IntegratorOptions(method="dop853"),
        "d5t": tslip.IntegratorOptions(rtol=1e-12, atol=1e-12),
        "d853t": tslip.IntegratorOptions(rtol=1e-12, atol=1e-12, method="dop853"),
        "d5l": tslip.IntegratorOptions(rtol=1e-5, atol=1e-6),
    }
    params = {n: tslip.preset(n) for n in presets()}
    params["soft"] = dataclasses.replace(tslip.preset("table2.1-local-velocity"), k=5.0)
    params["apex"] = dataclasses.replace(tslip.preset("table2.1"), retraction="apex")
    for pn, p in params.items():
        for sn, s in states.items():
            for on, o in opts.items():
                key = f"{pn}/{sn}/{on}"
                r = tslip.step_map(p, np.array(s), options=o, h=0.01 if sn == "s2" else 0.0)
                res[f"map/{key}"] = np.r_[r.q, r.stance_time, r.flight_time, int(r.status)]
                rj, J = tslip.step_jacobian(p, np.array(s), options=o)
                res[f"jac/{key}"] = np.r_[rj.q, J.ravel(), int(rj.status)]
                st = tslip.step(p, np.array(s), options=o)
                res[f"step/{key}"] = np.r_[st.stance_time, st.flight_time, int(st.status),
                                           np.ravel(st.grf)]
                P, O = pk.pack_params(p), o.packed()
                out = np.empty(pk.NOUT)
                stt = _packed.stride_map(P, O, np.array(s), 0.0, out)
                res[f"pmap/{key}"] = np.r_[_old_out(out, pk), stt]
                J2, out2 = np.empty((5, 5)), np.empty(pk.NOUT)
                _packed._JACOBIANS.clear()
                stt = _packed.stride_jacobian(P, O, np.array(s), 0.0, J2, out2)
                res[f"pjac/{key}"] = np.r_[J2.ravel(), _old_out(out2, pk), stt]
                if on in ("d5", "d853", "d5t"):
                    td = tslip.TouchdownState.from_section(np.array(s))
                    tr = tslip.simulate(p, td, 4, dt=0.013, options=o)
                    res[f"sim/{key}"] = tr.data.ravel()
                    tr = tslip.simulate(p, td, 3, options=o,
                                        disturbance=tslip.Disturbance(at_step=1, dh=-0.05,
                                                                      dxd=0.1))
                    res[f"simd/{key}"] = tr.data.ravel()
                    # stance recorded on a uniform grid and at steps, straight from the kernel
                    y0 = np.empty(6)
                    kn.stance_initial(P, td.as_array(), y0)
                    for dt in (0.0, 0.0013):
                        rec = np.empty((20000, pk.NREC))
                        stats = np.empty(5)
                        yout = np.empty(6)
                        c = kn.integrate_stance(P, O, y0, yout, rec, dt, stats)
                        rows = _old_rec(rec[: int(stats[3])], P, dt <= 0.0, pk)
                        res[f"stance{dt}/{key}"] = np.r_[rows.ravel(), yout, stats, c]
        # batches: serial and parallel, with terrain
        S = np.array([states["s1"], states["s2"], states["s3"], states["slow"]] * 5)
        terr = [tslip.Terrain.step(0.4, -0.02 * i) for i in range(len(S))]
        for on in ("d5", "d853"):
            o = opts[on]
            b = tslip.run_batch(p, S[:3], 5, options=o)
            res[f"rb3/{pn}/{on}"] = np.r_[b.touchdowns.ravel(), b.status, b.n_done, b.t_fall]
            b = tslip.run_batch(p, S, 5, options=o, terrain=terr)
            res[f"rb20/{pn}/{on}"] = np.r_[b.touchdowns.ravel(), b.status, b.n_done, b.t_fall]
            b = tslip.step_batch(p, S, options=o, terrain=terr)
            res[f"sb20/{pn}/{on}"] = np.r_[_old_out(b.raw, pk).ravel(), b.status]
            b = tslip.step_batch(p, S[:2], options=o)
            res[f"sb2/{pn}/{on}"] = np.r_[_old_out(b.raw, pk).ravel(), b.status]
    for pn in ("table2.1", "table6.1"):
        g = tslip.find_gait(tslip.preset(pn))
        res[f"gait/{pn}"] = np.r_[g.state.as_array(), g.params.alpha_r]
        fl = tslip.gait.floquet(g) if hasattr(tslip.gait, "floquet") else None
        if fl is not None:
            res[f"floq/{pn}"] = np.r_[np.abs(np.asarray(fl.multipliers))]
    np.savez(path, **{k.replace("/", "|"): np.asarray(v, dtype=float) for k, v in res.items()})
    print(len(res), "arrays")


def compare(a: str, b: str) -> int:
    A, B = np.load(a), np.load(b)
    bad = 0
    worst = 0.0
    if set(A.files) != set(B.files):
        print("key sets differ", set(A.files) ^ set(B.files))
        bad += 1
    for k in sorted(set(A.files) & set(B.files)):
        x, y = A[k], B[k]
        if x.shape != y.shape or not np.array_equal(x.view(np.uint64), y.view(np.uint64)):
            bad += 1
            if x.shape != y.shape:
                print("DIFF", k, x.shape, y.shape)
                continue
            # how far: the largest difference relative to the array's largest value
            # (where NaN sits in both, it counts as equal)
            both = np.isnan(x) & np.isnan(y)
            d = np.where(both, 0.0, np.abs(x - y))
            scale = np.nanmax(np.abs(x)) if np.isfinite(x).any() else 1.0
            rel = np.nanmax(d) / scale if scale > 0 else np.nanmax(d)
            worst = max(worst, rel)
            print(f"DIFF {k} {x.shape}: {int((d != 0).sum())} values, largest difference "
                  f"{rel:.2e} of the array's largest value")
    print(f"{len(A.files)} arrays compared, {bad} differ"
          + (f" (largest relative difference {worst:.2e})" if bad else ""))
    return bad


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(sys.argv[2])
    else:
        sys.exit(1 if compare(sys.argv[2], sys.argv[3]) else 0)
