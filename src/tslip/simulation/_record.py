"""Compiled recorded runs (``tslip.simulate``): strides sampled into compact rows.

Private (see :mod:`._kernels`). :data:`RECORD_RUN` holds one kernel per
integrator method (:func:`._stride.specialise`): the strides and their stance
record rows (time and stance state) as the stride kernel writes them.
:func:`fill_table` derives the trajectory's columns from those when they are first
read (the row builders are ``inline="always"``), so a run that is not looked at row
by row never pays for them; :func:`stance_forces` derives a stride's ground force
and hip torque (``StepResult.grf``). Both compute the forces as the stride kernel's
:func:`._stance.grf` would (:func:`._stance.grf_at`), bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import (
    NOUT,
    NTD,
    OUT_LO,
    OUT_NREC,
    OUT_RECOVF,
    OUT_TD,
    OUT_TF,
    OUT_TS,
    OUT_TSW,
    OUT_XF,
    P_G,
    P_J,
    P_L0,
    P_M,
    P_R,
    P_THRUST,
    REC_BETA,
    REC_BETAD,
    REC_L,
    REC_LD,
    REC_PHI,
    REC_PHID,
    REC_T,
    RI_LOFY,
    RI_NSTANCE,
    RI_ROW0,
    RI_ROW1,
    RI_STATUS,
    RI_T0,
    RI_TDY,
    RUN_FULL,
    ST_OK,
    TR_ALPHA,
    TR_BETA,
    TR_BETAD,
    TR_ENERGY,
    TR_FOOTX,
    TR_FOOTY,
    TR_FX,
    TR_FY,
    TR_HIPX,
    TR_HIPY,
    TR_L,
    TR_LD,
    TR_PHI,
    TR_PHID,
    TR_STANCE,
    TR_STEP,
    TR_T,
    TR_TAU,
    TR_X,
    TR_XD,
    TR_Y,
    TR_YD,
)
from ._flight import flight_leg_angle, flight_state, retraction_start
from ._rk import _INLINE, _JIT
from ._specialise import specialise
from ._stance import _com_velocity, grf_at, spring_energy
from ._stride import stride_of


@njit(**_INLINE)
def _energy(P, y, xd, yd, phid, l):
    """Total mechanical energy: kinetic + gravity + leg spring ``V`` [MgL]."""
    return (0.5 * P[P_M] * (xd * xd + yd * yd) + 0.5 * P[P_J] * phid * phid
            + P[P_M] * P[P_G] * y + spring_energy(P, l))


@njit(**_INLINE)
def _stance_row(P, t0, i, xf, h, rows, k, tab):
    """Trajectory column ``k`` of ``tab`` from the stance record row ``rows[k]`` (eq.
    A.3-A.5: CoM, hip from the leg; eqs 2.5-2.6: the ground force).

    Indices, not a row view and a column view per sample: those cost 3-9 % of
    :func:`fill_table` (numba counts their references)."""
    rp = P[P_R]
    l, b, ph = rows[k, REC_L], rows[k, REC_BETA], rows[k, REC_PHI]
    ld, bd, phd = rows[k, REC_LD], rows[k, REC_BETAD], rows[k, REC_PHID]
    sb = math.sin(b)
    cb = math.cos(b)
    sp = math.sin(ph)
    cp = math.cos(ph)
    y = h + l * sb - rp * cp
    xd, yd = _com_velocity(rp, l, sb, cb, sp, cp, ld, bd, phd)
    tab[TR_T, k] = t0 + rows[k, REC_T]
    tab[TR_STEP, k] = i
    tab[TR_STANCE, k] = 1.0
    tab[TR_X, k] = xf - l * cb + rp * sp
    tab[TR_Y, k] = y
    tab[TR_XD, k] = xd
    tab[TR_YD, k] = yd
    tab[TR_PHI, k] = ph
    tab[TR_PHID, k] = phd
    tab[TR_L, k] = l
    tab[TR_BETA, k] = b
    tab[TR_LD, k] = ld
    tab[TR_BETAD, k] = bd
    tab[TR_ALPHA, k] = b + ph
    tab[TR_FOOTX, k] = xf
    tab[TR_FOOTY, k] = h
    tab[TR_HIPX, k] = xf - l * cb
    tab[TR_HIPY, k] = h + l * sb
    tab[TR_FX, k], tab[TR_FY, k], tab[TR_TAU, k] = grf_at(P, l, ph, ld, bd, phd, sb, cb)
    tab[TR_ENERGY, k] = _energy(P, y, xd, yd, phd, l)


@njit(**_INLINE)
def _flight_row(P, t_lo, i, lo, tau, fs, tab, c):
    """Column ``c`` of ``tab``: the state ``tau`` after lift-off at ``t_lo`` (closed-form
    flight, eq. 2.7)."""
    flight_state(P, lo, tau, fs)
    l0 = P[P_L0]
    tab[TR_T, c] = t_lo + tau
    tab[TR_STEP, c] = i
    tab[TR_STANCE, c] = 0.0
    for j in range(6):  # x, y, xd, yd, phi, phid
        tab[TR_X + j, c] = fs[j]
    tab[TR_L, c] = l0
    tab[TR_BETA, c] = fs[6]
    tab[TR_LD, c] = 0.0
    tab[TR_BETAD, c] = flight_leg_angle(P, lo[4], lo[5], tau, retraction_start(P, lo[3]))[1]
    tab[TR_ALPHA, c] = fs[6] + fs[4]
    tab[TR_FOOTX, c] = fs[7]
    tab[TR_FOOTY, c] = fs[8]
    tab[TR_HIPX, c] = fs[0] - P[P_R] * math.sin(fs[4])
    tab[TR_HIPY, c] = fs[9]
    tab[TR_FX, c] = 0.0
    tab[TR_FY, c] = 0.0
    tab[TR_TAU, c] = 0.0
    tab[TR_ENERGY, c] = _energy(P, fs[1], fs[2], fs[3], fs[5], l0)


@njit(**_INLINE)
def n_flight_samples(tf, dt, final):
    """Flight samples of a stride: ``dt, 2 dt, ...`` strictly before ``tf`` (those within
    1e-9 of it dropped: the next touch-down row follows), plus ``tf`` itself if ``final``."""
    n = max(0, int(math.ceil((tf - dt) / dt))) if tf > dt else 0
    if n > 0 and tf - (dt + (n - 1) * dt) < 1e-9:
        n -= 1
    return n + 1 if final else n


def _make_record_run(method: int) -> Callable:
    def record_run(P, O, td, tx, th, first, last, close, dt, rows, starts, outs, info, pos):
        """Strides ``first .. last - 1`` of a run, sampled every ``dt`` into compact rows.

        Starts from the touch-down state ``td`` (7) at time ``pos[1]`` and writes
        from row ``pos[0]`` of ``rows`` (n x NREC), one row per trajectory sample:
        each stance's record rows as the stride kernel writes them (``REC_*``: time
        since touch-down and stance state, on the grid of
        :func:`._stride._make_stride`, touch-down and lift-off rows included), then
        one row per flight sample holding only its time since lift-off in ``REC_T``
        (``dt, 2 dt, ...``, and the touch-down instant closing the last stride if
        ``close``; otherwise the next stride's first row is that instant). Stride
        ``s`` fills ``starts[s]`` (its touch-down state), ``outs[s]``
        (:func:`._stride._make_stride`'s output) and ``info[s]`` (``RI_*``).
        :func:`fill_table` derives the trajectory's columns (forces included) from
        them when they are first read.

        Returns the status of the last stride run (it stops at the first that is
        not OK), or ``RUN_FULL`` if the next stride's rows would not fit; then
        ``td``, ``pos = (row, t0, stride)`` say where to resume with more rows.
        """
        out = np.empty(NOUT)
        lo = np.empty(6)
        row = int(pos[0])
        t0 = pos[1]
        nmax = rows.shape[0]
        status = ST_OK
        for s in range(first, last):
            pos[0] = row
            pos[1] = t0
            pos[2] = s
            if nmax - row < 2:
                return RUN_FULL
            status = stride_of(method, P, O, td, tx, th, rows[row:], dt, out)
            if out[OUT_RECOVF] != 0.0:
                return RUN_FULL
            nrec = int(out[OUT_NREC])
            ts = out[OUT_TS]
            tf = out[OUT_TF]
            final = status != ST_OK or (close and s == last - 1)
            nfl = n_flight_samples(tf, dt, final) if tf > 0.0 else 0
            if row + nrec + nfl > nmax:
                return RUN_FULL
            for k in range(nfl):
                tau = dt + k * dt
                if final and k == nfl - 1:
                    tau = tf
                rows[row + nrec + k, REC_T] = tau
            for j in range(6):
                lo[j] = out[OUT_LO + j]
            for j in range(NTD):
                starts[s, j] = td[j]
            for j in range(NOUT):
                outs[s, j] = out[j]
            inf = info[s]
            inf[RI_T0] = t0
            inf[RI_ROW0] = row
            inf[RI_NSTANCE] = nrec
            inf[RI_ROW1] = row + nrec + nfl
            inf[RI_STATUS] = status
            inf[RI_TDY] = td[6] + P[P_L0] * math.sin(td[0]) - P[P_R] * math.cos(td[1])
            inf[RI_LOFY] = (lo[1] + P[P_R] * math.cos(lo[4])) - out[OUT_LO + 6] * math.sin(
                out[OUT_LO + 7])
            row += nrec + nfl
            pos[0] = row
            pos[2] = s + 1
            if status != ST_OK:
                break
            t0 = t0 + ts + tf
            pos[1] = t0
            for j in range(NTD):
                td[j] = out[OUT_TD + j]
        return status

    return record_run


@njit(**_INLINE)
def after_switch(t, tsw, at_steps):
    """Whether the record row at ``t`` holds a state the kernel integrated with the leg
    thrust's switched rest length (switch at ``tsw``; NaN without one: never). Rows
    recorded at each accepted step (``at_steps``) are so from ``t >= tsw`` on, the
    switch's own row included; grid rows only from ``t > tsw``: a grid row at ``tsw`` was
    sampled from the step that ends there, before the switch."""
    return t >= tsw if at_steps else t > tsw


@njit(**_JIT)
def fill_table(P, rows, starts, outs, info, n, table):
    """The trajectory columns (``TR_*``, one row of ``table`` each) of a recorded run.

    ``rows``, ``starts``, ``outs`` and ``info`` hold strides ``0 .. n - 1`` as
    :func:`_make_record_run`'s ``record_run`` wrote them; ``table`` is
    ``NTRAJ x rows`` (column-major: a column of the trajectory is a row here).
    Stance rows come from the record rows by eqs A.3-A.5 (their forces by eqs
    2.5-2.6), flight rows from the lift-off state in closed form (eq. 2.7). A stance
    row after the leg thrust's switch (``OUT_TSW``) takes the switched rest length,
    as the stride kernel's grid did (:func:`stance_forces`).
    """
    lo = np.empty(6)
    fs = np.empty(10)
    Pw = P.copy()  # the switched parameters of a thrust's stance rows
    Pw[P_THRUST] = -P[P_THRUST]
    for s in range(n):
        t0 = info[s, RI_T0]
        row = int(info[s, RI_ROW0])
        nrec = int(info[s, RI_NSTANCE])
        xf = outs[s, OUT_XF]
        h = starts[s, 6]
        tsw = outs[s, OUT_TSW]  # NaN without a switch: no row is after it
        for k in range(row, row + nrec):
            Pk = Pw if after_switch(rows[k, REC_T], tsw, False) else P
            _stance_row(Pk, t0, s, xf, h, rows, k, table)
        t_lo = t0 + outs[s, OUT_TS]
        for j in range(6):
            lo[j] = outs[s, OUT_LO + j]
        for k in range(row + nrec, int(info[s, RI_ROW1])):
            _flight_row(P, t_lo, s, lo, rows[k, REC_T], fs, table, k)


@njit(**_JIT)
def stance_forces(P, rec, tsw, at_steps, grf):
    """A stance's ground force and hip torque from its record rows ``rec`` (n x NREC):
    ``grf`` (n x 4) receives ``t, F_x, F_y, tau`` (``StepResult.grf``) as the stride
    kernel computes them (:func:`._stance.grf`), bit for bit.

    With a leg thrust the kernel ran on the switched rest length from the switch on
    (``tsw``, its ``OUT_TSW``): which rows that covers depends on how they were recorded,
    at each accepted step (``at_steps``, :func:`tslip.step`) or on the grid
    (``tslip.simulate``, as :func:`fill_table` reads them): :func:`after_switch`.
    """
    Pw = P.copy()  # the switched parameters of a thrust's rows after the switch
    Pw[P_THRUST] = -P[P_THRUST]
    for k in range(rec.shape[0]):
        r = rec[k]
        t = r[REC_T]
        b = r[REC_BETA]
        Pk = Pw if after_switch(t, tsw, at_steps) else P
        grf[k, 0] = t
        grf[k, 1], grf[k, 2], grf[k, 3] = grf_at(Pk, r[REC_L], r[REC_PHI], r[REC_LD],
                                                 r[REC_BETAD], r[REC_PHID], math.sin(b),
                                                 math.cos(b))


#: ``(P, O, td, tx, th, first, last, close, dt, rows, starts, outs, info, pos)
#: -> status`` by method (:func:`_make_record_run`).
RECORD_RUN = specialise(_make_record_run, "record_run")


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(_stance_row, __file__)
