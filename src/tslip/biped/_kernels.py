"""Compiled biped kernels: TMT dynamics, contact, controller, Runge-Kutta with events.

Private. Arguments are float64 arrays, floats and ints; results are arrays and
an int status (codes in :mod:`._pack`). Everything also runs with
``NUMBA_DISABLE_JIT=1``.

This module gathers the kernels of one concept each:

* :mod:`._tmt`: kinematics, mass matrix and bias forces (eqs E.1-E.22);
* :mod:`._control`: controller phases, references and actuation (eqs E.25-E.34);
* :mod:`._contact`: foot state and ground contact (eqs E.23-E.24);
* :mod:`._rhs`: the right-hand side (eq. E.22);
* :mod:`._events`: the switching functions (contact, controller, falls);
* :mod:`._stride`: the stride loop, Runge-Kutta steps with events (:func:`run`).
"""

from __future__ import annotations

from ._contact import (
    contact_force,
    contact_force_trig,
    contact_law,
    contact_switch,
    foot_state,
    foot_state_of,
    foot_state_trig,
    init_contact,
)
from ._control import (
    NRC,
    PHASE_EPS,
    actuation,
    ctl_phase,
    ctl_switch,
    ctl_switch_time,
    init_ctl,
    leg_phase,
    references,
    references_at,
    references_branch,
)
from ._events import (
    K_CTL,
    K_FALL,
    NEVK,
    event_g,
    event_value,
    event_value_trig,
    fall_check,
    fall_value,
    state_trig,
)
from ._jit import FOOT, NB, N
from ._rhs import _make_ws, make_workspace, rhs
from ._stride import dense_output, make_work, rk_step, run
from ._tmt import (
    NBLK,
    _make_kin_ws,
    block_solve,
    body_props,
    energy,
    kinematics,
    make_kin_workspace,
    mass_matrix_and_bias,
    tmt_blocks,
)

__all__ = [
    "FOOT", "K_CTL", "K_FALL", "N", "NB", "NBLK", "NEVK", "NRC", "PHASE_EPS", "actuation",
    "block_solve", "body_props", "contact_force", "contact_force_trig", "contact_law",
    "contact_switch", "ctl_phase", "ctl_switch", "ctl_switch_time", "dense_output", "energy",
    "event_g", "event_value", "event_value_trig", "fall_check", "fall_value", "foot_state",
    "foot_state_of", "foot_state_trig", "init_contact", "init_ctl", "kinematics", "leg_phase",
    "make_kin_workspace", "make_work", "make_workspace", "mass_matrix_and_bias", "references",
    "references_at", "references_branch", "rhs", "rk_step", "run", "state_trig", "tmt_blocks",
    "_make_kin_ws", "_make_ws",
]
