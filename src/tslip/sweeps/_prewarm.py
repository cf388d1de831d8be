"""Importing this module compiles (or loads) the kernel families not cached yet.

The worker pool's fork server imports it last among the tasks' modules
(``preload`` of :func:`tslip.sweeps._pool.process_pool`), before it forks
any worker: each missing kernel is then compiled once, here, instead of in
every worker at once, and the workers start with every kernel in memory.
Only the families of the subpackages the task modules imported are warmed
(a study needs no biped kernels), and none another process has claimed
(``tslip reproduce`` warms the biped's and the recorded runs' itself, and the
tasks that need them wait for them). See :mod:`tslip.sweeps._warmup`.
"""

from __future__ import annotations

import sys

from ._warmup import warm_missing

warm_missing(tuple(p for p in ("simulation", "biped") if f"tslip.{p}" in sys.modules))
