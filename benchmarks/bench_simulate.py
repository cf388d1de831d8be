"""A recorded run: ``tslip.simulate`` now vs revision 1b54594 (recording in Python).

Run by hand (not in CI): ``python benchmarks/bench_simulate.py``. Workloads, on
the Table 6.1 periodic gait (``tslip.find_gait(tslip.preset("table6.1"))``),
default options, sampled every ``dt`` (default 0.01):

* ``plain``: ``--steps`` strides (default 1000) on flat ground (target: 20x);
* ``disturbed``: the same with a push and a step down at stride 10;
* ``rough``: the same on random ground (heights within +-``--rough`` every half
  metre of the path).

Each is timed here and on :data:`_baseline.BASELINE_REV` in a subprocess in the
same invocation, alternately for ``--rounds`` rounds of best-of-``--repeat``
(the best of all counts), so the ratio is what counts on a shared machine. For
reference, the same strides as a Python loop over ``step_map`` (no recording)
are timed too.
"""

from __future__ import annotations

import argparse

from _baseline import BASELINE_REV, best_of, run_at

SETUP = """
import numpy as np, tslip
g = tslip.find_gait(tslip.preset("table6.1"))
p, s = g.params, g.state
rng = np.random.default_rng(0)
xs = np.arange(1.0, 2.0 * {steps}, 0.5)
rough = tslip.Terrain.sequence(xs.tolist(), rng.uniform(-{rough}, {rough}, xs.size + 1).tolist())
push = tslip.Disturbance(at_step=10, dh=-0.02, dxd=0.05)
def step_map_loop(n):
    q = s.section()
    for _ in range(n):
        q = tslip.step_map(p, q).q
"""

WORKLOADS = {
    "plain": "tr = tslip.simulate(p, s, {steps}, dt={dt})",
    "disturbed": "tr = tslip.simulate(p, s, {steps}, dt={dt}, disturbance=push)",
    "rough": "tr = tslip.simulate(p, s, {steps}, terrain=rough, dt={dt})",
}


def best_here(setup: str, stmt: str, repeat: int) -> tuple[float, dict]:
    """Best-of-``repeat`` seconds of ``stmt`` on this checkout (after one warm call)."""
    ns: dict = {}
    exec(setup, ns)
    code = compile(stmt, "<stmt>", "exec")
    return best_of(lambda: exec(code, ns), repeat), ns


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--dt", type=float, default=0.01)
    ap.add_argument("--rough", type=float, default=0.005, help="ground height amplitude [L]")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    setup = SETUP.format(steps=a.steps, rough=a.rough)
    print(f"Table 6.1 gait, {a.steps} strides, dt = {a.dt}; best of {a.rounds} x {a.repeat}; "
          f"baseline revision {BASELINE_REV}")
    print(f"{'workload':<11} {'strides':>7} {'rows':>8} {'now [ms]':>9} {'then [ms]':>10} "
          f"{'speed-up':>9}")
    for name, stmt in WORKLOADS.items():
        stmt = stmt.format(steps=a.steps, dt=a.dt)
        now = then = float("inf")
        for _ in range(a.rounds):
            t, ns = best_here(setup, stmt, a.repeat)
            now = min(now, t)
            then = min(then, run_at(BASELINE_REV, setup, stmt, repeat=a.repeat))
        tr = ns["tr"]
        print(f"{name:<11} {len(tr.steps):>7} {len(tr.data):>8} {now * 1e3:>9.1f} "
              f"{then * 1e3:>10.1f} {then / now:>8.1f}x")
        if name == "plain":
            plain = now
    loop = min(best_here(setup, f"step_map_loop({a.steps})", a.repeat)[0]
               for _ in range(a.rounds))
    print(f"reference: {a.steps} step_map calls (no recording) {loop * 1e3:.1f} ms; "
          f"simulate / step_map loop = {plain / loop:.2f}")


if __name__ == "__main__":
    main()
