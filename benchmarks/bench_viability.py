"""A 100 x 100 SLIP state-action map: tslip's batched kernels against scipy's solve_ivp.

Run by hand (not in CI): ``python benchmarks/bench_viability.py``. The
grid (issue 13, item 4): preset ``slip``, total energy 2.6 (where the SLIP
has both fixed points, e.g. apex heights near 0.94 and 1.44 at alpha_r =
1.15), apex heights ``y`` in [0.8, 2.5] x touch-down angles ``alpha_r`` in
[1.0, 1.45], 100 x 100 cells, tolerance 1e-12 (DOP853 in both).

* tslip: :func:`tslip.gait.viability.state_action_map` (every cell in one
  batched compiled call), best of ``--repeat`` after a warm-up, with numba's
  default threads and on one thread; plus :func:`viability` on the result.
* scipy: the same map written here, apex -> touch-down in closed form ->
  stance by ``solve_ivp(method="DOP853", rtol=atol=1e-12)`` with a lift-off
  event -> apex, one cell at a time. It is timed on ``--sample`` random
  cells and **extrapolated** to the whole grid (the output says so).

Printed: both times, their ratio, and the largest difference in next-apex
height over the sampled cells where both find a next apex (and how many
cells disagree on whether there is one).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _baseline import best_of  # noqa: E402

ENERGY = 2.6


def scipy_apex(p, y: float, alpha: float, energy: float) -> float:  # noqa: ANN001
    """Next apex height of the SLIP (point mass on a massless spring leg), NaN if none."""
    from scipy.integrate import solve_ivp

    m, g, k, l0 = p.m, p.g, p.k, p.l0
    drop = y - l0 * math.sin(alpha)
    if drop <= 0.0:
        return math.nan  # the foot is not above the ground at the apex
    xd = math.sqrt(2.0 * (energy - m * g * y) / m)
    foot = l0 * math.cos(alpha)

    def rhs(_t, s):  # noqa: ANN001, ANN202
        dx, dy = s[0] - foot, s[1]
        ell = math.hypot(dx, dy)
        f = k * (l0 - ell) / (m * ell)
        return [s[2], s[3], f * dx, f * dy - g]

    def liftoff(_t, s):  # noqa: ANN001, ANN202
        return math.hypot(s[0] - foot, s[1]) - l0

    def ground(_t, s):  # noqa: ANN001, ANN202
        return s[1]

    liftoff.terminal, liftoff.direction = True, 1.0  # type: ignore[attr-defined]
    ground.terminal = True  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, l0 * math.sin(alpha), xd,
                                       -math.sqrt(2.0 * g * drop)],
                    method="DOP853", rtol=1e-12, atol=1e-12, events=[liftoff, ground])
    if not len(sol.t_events[0]):
        return math.nan  # fell in stance
    _, y_lo, vx, vy = sol.y_events[0][0]
    if vy < 0.0 or vx < 0.0:
        return math.nan  # no apex (lift-off moving down) or moving backward
    return y_lo + vy * vy / (2.0 * g)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="grid points per axis")
    ap.add_argument("--sample", type=int, default=200, help="scipy cells timed")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    import numba

    import tslip
    from tslip.gait.viability import state_action_map, viability

    p = tslip.preset("slip")
    y = np.linspace(0.8, 2.5, args.n)
    a = np.linspace(1.0, 1.45, args.n)

    def run():  # noqa: ANN202
        return state_action_map(p, {"y": y}, ("alpha_r", a), energy=ENERGY)

    m = run()
    t_new = best_of(run, args.repeat)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    t_one = best_of(run, args.repeat)
    c_one = best_of(run, args.repeat, clock=time.process_time)
    numba.set_num_threads(threads)
    t_v = best_of(lambda: viability(m), args.repeat)
    v = viability(m)

    rng = np.random.default_rng(0)
    cells = rng.choice(m.status.size, size=min(args.sample, m.status.size), replace=False)
    t0, c0 = time.perf_counter(), time.process_time()
    ref = np.array([scipy_apex(p, y[c // args.n], a[c % args.n], ENERGY) for c in cells])
    t_sample, c_sample = time.perf_counter() - t0, time.process_time() - c0
    t_scipy = t_sample * m.status.size / len(cells)

    got = m.next[..., 0].ravel()[cells]
    both = np.isfinite(got) & np.isfinite(ref)
    disagree = int(np.sum(np.isfinite(got) != np.isfinite(ref)))
    j = int(np.argmin(np.abs(a - 1.15)))
    d = m.next[:, j, 0] - y
    roots = [f"{0.5 * (y[i] + y[i + 1]):.3f}" for i in range(len(y) - 1)
             if np.isfinite(d[i]) and np.isfinite(d[i + 1]) and d[i] * d[i + 1] < 0]

    print(f"SLIP state-action map, {args.n} x {args.n} cells (y in [0.8, 2.5] x alpha_r in "
          f"[1.0, 1.45]), energy {ENERGY}, tolerance 1e-12, DOP853")
    print(f"  fixed points at alpha_r = {a[j]:.3f}: y ~ {', '.join(roots)}; "
          f"{int(m.failed.sum())} cells fail, {v}")
    c_scipy = c_sample * m.status.size / len(cells)
    print(f"tslip state_action_map : {t_new:8.3f} s wall ({threads} threads); one thread "
          f"{t_one:.3f} s wall, {c_one:.3f} s CPU; viability iteration {t_v * 1e3:.1f} ms")
    print(f"scipy solve_ivp        : {t_scipy:8.3f} s wall, {c_scipy:.3f} s CPU, EXTRAPOLATED "
          f"from {len(cells)} random cells ({t_sample:.2f} s for those, one thread)")
    print(f"ratio scipy / tslip    : {t_scipy / t_new:8.1f}x wall; one thread "
          f"{t_scipy / t_one:.1f}x wall, {c_scipy / c_one:.1f}x CPU")
    print(f"largest |next-apex height difference| over {int(both.sum())} compared cells: "
          f"{np.max(np.abs(got[both] - ref[both])):.2e} L; {disagree} cells disagree on "
          "whether there is a next apex")


if __name__ == "__main__":
    main()
