"""The only bridge between typed Python objects and the compiled kernels.

Kernels see flat float64 arrays. This module fixes their layout with named
index constants; nothing else in the package indexes them by number.
"""

from __future__ import annotations

import numpy as np

from .parameters import Params

# -- parameter vector P ------------------------------------------------------
P_M, P_J, P_R, P_K, P_L0, P_G, P_CL, P_OMEGA, P_ALPHA, P_GLOBAL, P_CTRL = range(11)
P_C0 = 11  # tau = P[P_C0] + P[P_C0+1] phi + P[P_C0+2] betad + P[P_C0+3] phid
P_APEX = 15  # 1.0: the retraction clock starts at the flight apex (retraction="apex")
P_NEXP = 16  # leg spring exponent n (1: the linear spring of eq. 2.1)
P_THRUST = 17  # leg thrust d >= 0; a stance's working copy holds -d once its rest length switched
P_STOP = 18  # retraction stop angle alpha_stop in (0, pi); 0.0: none
NP = 19

# -- integrator options O ----------------------------------------------------
O_RTOL, O_ATOL, O_H0, O_MAXSTEPS, O_TMAX_STANCE, O_TMAX_FLIGHT, O_HMIN, O_METHOD = range(8)
NO = 8

# -- Runge-Kutta pair codes (O[O_METHOD]; also the biped's options) -----------
M_DOPRI5, M_DOP853 = 0, 1
METHODS = ("dopri5", "dop853")  # name of each code

# -- touch-down state TD (7) -------------------------------------------------
TD_BETA, TD_PHI, TD_XD, TD_YD, TD_PHID, TD_X, TD_H = range(7)
NTD = 7

# -- stance state y (6) --------------------------------------------------------
Y_L, Y_BETA, Y_PHI, Y_LD, Y_BETAD, Y_PHID = range(6)

# -- stride output vector OUT ----------------------------------------------------
OUT_TD = 0  # 7 values: next touch-down state
OUT_TS = 7  # stance time
OUT_TF = 8  # flight time
OUT_LO = 9  # 10 values: lift-off x_m, y_m, xd, yd, phi, phid, l, beta, ld, betad
OUT_CLEAR = 19  # foot height above ground right after the leg reset
OUT_XF = 20  # foot x during the stance
OUT_NSTEP = 21  # accepted integrator steps in the stance
OUT_NREJ = 22  # rejected integrator steps
OUT_FYNEG = 23  # 1.0 if F_y < 0 right at touch-down
OUT_TFALL = 24  # time of the fall since touch-down (NaN if none)
OUT_NREC = 25  # number of recorded stance rows
OUT_RECOVF = 26  # 1.0 if the record buffer overflowed
OUT_TSW = 27  # time of the leg thrust's switch since touch-down (NaN if none)
NOUT = 28

# -- record row (time since touch-down, stance state y; the forces are derived from it) --
REC_T, REC_L, REC_BETA, REC_PHI, REC_LD, REC_BETAD, REC_PHID = range(7)
NREC = 7

# -- trajectory row (tslip.simulate; the columns of Trajectory.data) ------------------
TRAJ_COLUMNS = (
    "t", "step", "stance", "x", "y", "xd", "yd", "phi", "phid", "l", "beta", "ld", "betad",
    "alpha", "foot_x", "foot_y", "hip_x", "hip_y", "Fx", "Fy", "tau", "energy",
)
(TR_T, TR_STEP, TR_STANCE, TR_X, TR_Y, TR_XD, TR_YD, TR_PHI, TR_PHID, TR_L, TR_BETA, TR_LD,
 TR_BETAD, TR_ALPHA, TR_FOOTX, TR_FOOTY, TR_HIPX, TR_HIPY, TR_FX, TR_FY, TR_TAU,
 TR_ENERGY) = range(22)
NTRAJ = 22

# -- one recorded stride of a run (record_run's ``info`` row) --------------------
# touch-down time, first row, stance rows, end row (exclusive), status, CoM height
# at touch-down, foot height at lift-off
RI_T0, RI_ROW0, RI_NSTANCE, RI_ROW1, RI_STATUS, RI_TDY, RI_LOFY = range(7)
NRI = 7
RUN_FULL = -1  # record_run's return when the rows of the next stride do not fit

# -- status codes ---------------------------------------------------------------
ST_OK = 0
ST_FALL_BACKWARD = 1  # xdot_m < 0 (eq. 2.10)
ST_FALL_HIP_GROUND = 2  # hip at or below the ground in stance (eq. 2.11)
ST_FALL_NO_TOUCHDOWN = 3  # hip reaches the ground in flight before the foot
ST_FALL_TRIP = 4  # foot enters a higher terrain segment below its top (step riser)
ST_FALL_LENGTHENING = 5  # touch-down with the leg lengthening (ld > 0): it cannot push
ST_ERR_STEP_UNDERFLOW = 10
ST_ERR_MAX_STEPS = 11
ST_ERR_STANCE_TIMEOUT = 12
ST_ERR_FLIGHT_TIMEOUT = 13
ST_ERR_NONFINITE = 14
# 20+: outcomes that are neither a fall nor an error (the analyses set them, not the kernels)
ST_NO_APEX = 20  # the flight after lift-off has no apex (apex map); 21 is the biped's T_END


def packed_params(p: Params) -> np.ndarray:
    """``pack_params(p)``, packed once per ``Params`` instance and kept on it: never write into it.

    ``Params`` is frozen and checked when built, so a call that only reads the
    vector (``step_map``, ``simulate``) need neither check nor pack it again;
    callers that write unknowns into their vector take a fresh one from
    :func:`pack_params`.
    """
    try:
        return p._packed  # type: ignore[attr-defined]
    except AttributeError:
        out = pack_params(p)
        object.__setattr__(p, "_packed", out)
        return out


def pack_params(p: Params) -> np.ndarray:
    """``Params`` -> P vector (a new array)."""
    out = np.zeros(NP)
    out[P_M], out[P_J], out[P_R], out[P_K], out[P_L0], out[P_G] = p.m, p.J, p.r, p.k, p.l0, p.g
    out[P_CL], out[P_OMEGA], out[P_ALPHA] = p.c_l, p.omega_r, p.alpha_r
    out[P_GLOBAL] = 1.0 if p.leg_reset == "global" else 0.0
    out[P_APEX] = 1.0 if p.retraction == "apex" else 0.0
    out[P_NEXP], out[P_THRUST] = p.leg_exponent, p.leg_thrust
    out[P_STOP] = 0.0 if p.alpha_stop is None else p.alpha_stop
    out[P_CTRL] = p.controller.code
    out[P_C0 : P_C0 + 4] = p.controller.torque_coefficients()
    return out
