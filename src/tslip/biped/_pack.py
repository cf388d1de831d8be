"""Flat float64 layouts of the biped kernels: the only place that fixes indices."""

from __future__ import annotations

import numpy as np

from .parameters import BIPED_PARAMETER_TABLE, BipedParams

# -- parameter vector P (order of BIPED_PARAMETER_TABLE, then the two switches) ----------
(
    P_MB, P_JB, P_LT0, P_MT, P_JT, P_LS0, P_MS, P_JS, P_MF, P_R1, P_R2, P_G,
    P_KZ, P_CZ, P_KX, P_CX, P_D, P_T, P_RHO0, P_KPT, P_KDT, P_LTS, P_KPH, P_KDH,
    P_THF, P_THS, P_K, P_CL, P_ACT, P_CONTACT,
) = range(30)
NP = 30

# -- integrator options O ------------------------------------------------------------
(O_RTOL, O_ATOL, O_H0, O_HMAX, O_MAXSTEPS, O_TSTRIDE, O_TEND, O_FALLS, O_HMIN,
 O_METHOD) = range(10)  # O_METHOD: a code of tslip.model._pack.METHODS (0: dopri5)
NO = 10

# -- contact state CS: flags and touch-down anchors (eqs E.23-E.24) --------------------
CS_ON_R, CS_ON_L, CS_XR, CS_ZR, CS_XL, CS_ZL = range(6)
NCS = 6

# -- recorded rows: t, y (18), contact R/L, Fx_R, Fz_R, Fx_L, Fz_L, tau_R, tau_L,
#    F_tR, F_tL, F_sR, F_sL -------------------------------------------------------------
R_T = 0
R_Y = 1
R_CON = 19
R_F = 21  # Fx_R, Fz_R, Fx_L, Fz_L
R_TAU = 25  # tau_R, tau_L
R_FT = 27  # F_tR, F_tL
R_FS = 29  # F_sR, F_sL
NREC = 31

# -- event rows: t, kind, foot x, foot z -------------------------------------------------
EV_TD_R, EV_TD_L, EV_LO_R, EV_LO_L, EV_FALL = range(5)
NEV = 4

# -- stride rows (state just after each right touch-down): t, y (18), CS (6) --------------
NSTRIDE = 25

# -- stats ---------------------------------------------------------------------------
S_NREC, S_NEV, S_NSTRIDE, S_NACC, S_NREJ, S_TEND, S_NFEV, S_RECFULL = range(8)
NSTATS = 8

# -- statuses: the kernels' own codes, translated to the shared tslip.Status by name ----
#    (STATUS_NAMES, used by tslip.biped.simulate.to_status: the one boundary) ----------
ST_OK = 0
ST_TEND = 1
ST_FALL_HIP = 10
ST_FALL_BACKWARD = 11
ST_FALL_PITCH = 12
ST_FALL_LEG = 13
ST_FALL_NO_TD = 14
ST_ERR_MAX_STEPS = 20
ST_ERR_UNDERFLOW = 21
ST_ERR_NONFINITE = 22

#: Kernel code -> name of its :class:`tslip.Status` member (names, so that this
#: layout module, which the kernels import, imports nothing of the simulation).
STATUS_NAMES: dict[int, str] = {
    ST_OK: "OK",
    ST_TEND: "T_END",
    ST_FALL_HIP: "FALL_HIP_GROUND",
    ST_FALL_BACKWARD: "FALL_BACKWARD",
    ST_FALL_PITCH: "FALL_PITCH",
    ST_FALL_LEG: "FALL_LEG",
    ST_FALL_NO_TD: "FALL_NO_TOUCHDOWN",
    ST_ERR_MAX_STEPS: "MAX_STEPS",
    ST_ERR_UNDERFLOW: "STEP_UNDERFLOW",
    ST_ERR_NONFINITE: "NONFINITE",
}


def pack_params(p: BipedParams) -> np.ndarray:
    """``BipedParams`` -> ``P`` (float64, shape (NP,))."""
    vals = [float(getattr(p, row.name)) for row in BIPED_PARAMETER_TABLE]
    vals += [1.0 if p.actuated else 0.0, 1.0 if p.contact else 0.0]
    return np.array(vals, dtype=np.float64)
