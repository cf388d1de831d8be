"""A recorded run: ``tslip.simulate`` now vs revision 1b54594 (recording in Python).

Run by hand (not in CI): ``python benchmarks/bench_simulate.py``. Workloads, on
the Table 6.1 periodic gait (``tslip.find_gait(tslip.preset("table6.1"))``),
default options, sampled every ``dt`` (default 0.01):

* ``plain``: ``--steps`` strides (default 1000) on flat ground (target: 20x);
* ``disturbed``: the same with a push and a step down at stride 10;
* ``rough``: the same on random ground (heights within +-``--rough`` every half
  metre of the path).

The baseline :data:`_baseline.BASELINE_REV` is imported in this process
(``_baseline.import_at``), each workload built the same way on either
package, and old and new are timed interleaved, call by call, for
``--rounds`` rounds (``_baseline.ab``); the speed-up is printed from the best
and from the median times. How far the two trajectories differ is printed
too (they should agree to the integrator tolerance). For reference, the same
strides as a Python loop over ``step_map`` (no recording) are timed in the
``plain`` rounds too, and so is the floor: the same strides in one compiled
``run_batch`` call that records nothing, the least any recorded run of them
can cost at this integrator and tolerance (its ratio against the baseline is
the largest speed-up recording alone could give).
"""

from __future__ import annotations

import argparse
import types
from collections.abc import Callable

import numpy as np
from _baseline import BASELINE_REV, ab, import_at

import tslip


def workloads(ts: types.ModuleType, steps: int, dt: float,
              rough: float) -> dict[str, Callable[[], object]]:
    """The three runs (and the ``step_map`` loop) on package ``ts`` (``tslip`` or the old one)."""
    g = ts.find_gait(ts.preset("table6.1"))
    p, s = g.params, g.state
    rng = np.random.default_rng(0)
    xs = np.arange(1.0, 2.0 * steps, 0.5)
    ground = ts.Terrain.sequence(xs.tolist(), rng.uniform(-rough, rough, xs.size + 1).tolist())
    push = ts.Disturbance(at_step=10, dh=-0.02, dxd=0.05)

    def step_map_loop() -> None:
        q = s.section()
        for _ in range(steps):
            q = ts.step_map(p, q).q

    return {
        "floor": lambda: ts.run_batch(p, [s], steps),  # the same strides, nothing recorded
        "plain": lambda: ts.simulate(p, s, steps, dt=dt),
        "disturbed": lambda: ts.simulate(p, s, steps, dt=dt, disturbance=push),
        "rough": lambda: ts.simulate(p, s, steps, terrain=ground, dt=dt),
        "step_map loop": step_map_loop,
    }


def difference(a: np.ndarray, b: np.ndarray) -> str:
    """Largest difference of two recordings, or their shapes if those differ."""
    if a.shape != b.shape:
        return f"shapes {a.shape} vs {b.shape}"
    return f"{np.max(np.abs(a - b)):.1e}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--rough", type=float, default=0.005, help="ground height amplitude [L]")
    ap.add_argument("--rounds", type=int, default=10, help="interleaved new/old rounds")
    a = ap.parse_args()
    new = workloads(tslip, a.steps, a.dt, a.rough)
    old = workloads(import_at(BASELINE_REV), a.steps, a.dt, a.rough)
    print(f"Table 6.1 gait, {a.steps} strides, dt = {a.dt}; {a.rounds} interleaved rounds; "
          f"baseline revision {BASELINE_REV} in process")
    print(f"{'workload':<11} {'strides':>7} {'rows':>8} {'now [ms]':>9} {'then [ms]':>10} "
          f"{'speed-up':>9} {'(median)':>9}  max |now - then|")
    for name in ("plain", "disturbed", "rough"):
        fns = {"now": new[name], "then": old[name]}
        if name == "plain":
            fns["loop"] = new["step_map loop"]
            fns["floor"] = new["floor"]
        t = ab(fns, a.rounds)
        tr, tr_old = new[name](), old[name]()
        best, med = t.ratio("then", "now")
        print(f"{name:<11} {len(tr.steps):>7} {len(tr.data):>8} {t['now'] * 1e3:>9.1f} "
              f"{t['then'] * 1e3:>10.1f} {best:>8.1f}x {med:>8.1f}x  "
              f"{difference(tr.data, tr_old.data)}")
        if name == "plain":
            plain, plain_rows = t, len(tr.data)
    print(f"reference: {a.steps} step_map calls (no recording) {plain['loop'] * 1e3:.1f} ms; "
          f"simulate / step_map loop = {plain.ratio('now', 'loop')[0]:.2f} (median "
          f"{plain.ratio('now', 'loop')[1]:.2f})")
    floor, floor_med = plain.ratio("then", "floor")
    print(f"floor: the same {a.steps} strides in one compiled call with nothing recorded "
          f"(run_batch, one row) {plain['floor'] * 1e3:.1f} ms, so no recording can make "
          f"`plain` more than {floor:.1f}x (median {floor_med:.1f}x) faster than {BASELINE_REV} "
          f"at this integrator and tolerance; recording costs "
          f"{(plain['now'] - plain['floor']) * 1e3:.1f} ms "
          f"({(plain['now'] - plain['floor']) / plain_rows * 1e9:.0f} ns a row)")


if __name__ == "__main__":
    main()
