"""The TSLIP's compiled kernels, in one namespace.

Private. Arguments are float64 arrays, floats and ints; results are arrays plus
an int status (codes in :mod:`tslip.model._pack`). Nothing here prints or
builds Python objects, and everything also runs with ``NUMBA_DISABLE_JIT=1``.
The kernels live by concept:

* :mod:`._stance`: stance equations of motion, ground force, events;
* :mod:`._flight`: closed-form flight and the touch-down search;
* :mod:`._stepper`: the stance integrator (the :mod:`._rk` core with this ``rhs``);
* :mod:`._stride`: strides and batches;
* :mod:`._record`: the recorded run of ``tslip.simulate``;
* :mod:`._variational`: the exact stride Jacobian.

Each kernel is compiled once for both Runge-Kutta pairs: it reads the pair from
the options ``O`` it is given (``O[O_METHOD]``) at run time, and is called so
from Python and from other kernels alike. The readable reference for the equations is
:mod:`tslip.model.dynamics`; the tests check that both agree.
"""

from __future__ import annotations

import numpy as np

from .._kernel_cache import check as _check_cache
from ._flight import (
    alpha_r_column,
    find_touchdown,
    flight_leg_angle,
    flight_samples,
    flight_state,
    retraction_start,
    stop_angle,
    stop_binds,
    stop_time,
)
from ._record import record_run
from ._stance import (
    L_COLLAPSE,
    NEVENTS,
    NSTATE,
    com_velocity,
    event_values,
    grf,
    hip_torque,
    rhs,
    stance_accel,
    stance_initial,
)
from ._stride import (
    run_batch,
    run_batch_serial,
    run_row,
    section_map,
    stance_rec,
    stride,
    stride_batch,
    stride_batch_serial,
)

__all__ = [
    "L_COLLAPSE", "NEVENTS", "NSTATE", "alpha_r_column", "com_velocity",
    "event_values", "find_touchdown", "flight_leg_angle", "flight_samples", "flight_state",
    "grf", "hip_torque", "integrate_stance", "record_run", "retraction_start", "rhs",
    "run_batch", "run_batch_serial", "run_row", "section_map", "stance_accel",
    "stance_initial", "stop_angle", "stop_binds", "stop_time", "stride",
    "stride_batch", "stride_batch_serial",
]


_NO_TERRAIN = np.empty(0)


def integrate_stance(P: np.ndarray, O: np.ndarray, y0: np.ndarray,  # noqa: E741
                     yout: np.ndarray, rec: np.ndarray, rec_dt: float, stats: np.ndarray) -> int:
    """The stance alone from the stance state ``y0``, recorded into ``rec``
    (:func:`._stride.stance_rec`).

    ``yout`` receives the final state, ``stats`` ``[t_end, n_accepted, n_rejected,
    n_recorded, overflow]``; returns the status (see :func:`._stride.stride`).
    """
    out = np.empty(NSTATE + 5)
    status = stance_rec(P, O, y0, _NO_TERRAIN, _NO_TERRAIN, rec, rec_dt, out)
    yout[:] = out[:NSTATE]
    stats[:] = out[NSTATE:]
    return int(status)


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache). This
# module compiles nothing itself any more: the check clears its old entries.
_check_cache(find_touchdown, __file__)
