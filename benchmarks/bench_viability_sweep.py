"""Time per cell per sweep of the viability iteration, from 100 thousand to 10 million cells.

Run by hand (not in CI): ``python benchmarks/bench_viability_sweep.py``. A
synthetic compact successor map (no strides are integrated): a cubic grid
of states, 41 actions, each (state, action) row the 8 corners of a random
cell of the grid (int32 state indices, as
:func:`tslip.gait._viable.successor_cells` gives under ``"bracket"``), 5 %
of the rows failed (``-1``), and a chain of pairs that dies one layer of the grid
a sweep (:func:`synthetic`). For each size it times the chunked sweep
(:func:`tslip.gait._viable.viable_sets_chunked`, what :func:`viability` runs)
and, up to ``--old-max`` cells, the former whole-array iteration
(:func:`tslip.gait._viable.viable_sets` on int64 cells), best of
``--repeat``, and prints seconds per cell per pass (a pass is a sweep,
counting the last one that finds nothing to remove), CPU and wall.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from tslip.gait import _viable

N_ACTIONS = 41


def synthetic(n_cells: int, seed: int = 0) -> tuple[list[np.ndarray], int]:
    """Chunks of int32 corner indices for about ``n_cells`` rows, and the state count.

    Every action of a state in layer ``k`` of the grid's last axis leads into a
    random cell between layers ``k`` and ``k + 1``, and the top layer fails, except
    that in the lower half actions 0-19 lead into a random cell of the lower half:
    the upper half dies one layer a sweep (``side / 2`` sweeps), the lower half stays.
    """
    side = max(4, round((n_cells / N_ACTIONS) ** (1 / 3)))
    n_states = side**3
    half = side // 2
    rng = np.random.default_rng(seed)
    offsets = np.array([i * side * side + j * side + k for i in (0, 1) for j in (0, 1)
                        for k in (0, 1)], dtype=np.int64)
    chunks, rows = [], n_states * N_ACTIONS
    for a in range(0, rows, _viable.CHUNK_ROWS):
        r = np.arange(a, min(a + _viable.CHUNK_ROWS, rows))
        state, action = r // N_ACTIONS, r % N_ACTIONS
        k = state % side
        base = rng.integers(0, side - 1, size=(len(r), 3))
        stay = (k < half) & (action < 20)
        base[:, 2] = np.where(stay, rng.integers(0, half - 1, size=len(r)),
                              np.minimum(k, side - 2))
        b = base[:, 0] * side * side + base[:, 1] * side + base[:, 2]
        c = (b[:, None] + offsets[None, :]).astype(np.int32)
        c[(k == side - 1) | (rng.uniform(size=len(r)) < 0.02)] = -1
        chunks.append(c)
    return chunks, n_states


def timed(fn, repeat: int) -> tuple[float, float, object]:  # noqa: ANN001
    best_w = best_c = float("inf")
    out = None
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        best_w = min(best_w, time.perf_counter() - w)
        best_c = min(best_c, time.process_time() - c)
    return best_w, best_c, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e5, 1e6, 1e7])
    ap.add_argument("--old-max", type=float, default=1e7, help="largest size for the old way")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"{'cells':>10} {'way':>8} {'passes':>6} {'ns/cell/pass CPU':>17} {'wall':>8}")
    for size in args.sizes:
        chunks, n_states = synthetic(int(size))
        n = n_states * N_ACTIONS
        w, c, (q, _, sweeps) = timed(
            lambda c=chunks, n=n_states: _viable.viable_sets_chunked(c, n, N_ACTIONS),
            args.repeat)
        passes = sweeps + 1
        print(f"{n:10d} {'chunked':>8} {passes:6d} {1e9 * c / n / passes:17.2f} "
              f"{1e9 * w / n / passes:8.2f}", flush=True)
        if size <= args.old_max:
            cells = np.concatenate(chunks).astype(np.int64)
            ok = np.all(cells >= 0, axis=1)
            w, c, (q0, _, s0) = timed(
                lambda c=cells, o=ok, n=n_states: _viable.viable_sets(c, o, n), args.repeat)
            assert np.array_equal(q0, q) and s0 == sweeps
            print(f"{n:10d} {'whole':>8} {passes:6d} {1e9 * c / n / passes:17.2f} "
                  f"{1e9 * w / n / passes:8.2f}", flush=True)
            del cells, ok
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak resident memory {peak:.0f} MB")


if __name__ == "__main__":
    main()
