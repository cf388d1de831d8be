"""Compiled recorded runs (``tslip.simulate``): strides sampled into compact rows.

Private (see :mod:`._kernels`). :func:`record_run` is one kernel for both
integrator methods (the pair is read from the options ``O`` at run time, as the
stride kernel :func:`._stride.stride` it calls reads it): the strides and their
stance record rows (time and stance state) as the stride kernel writes them.
:func:`fill_table` derives the trajectory's columns from those when they are first
read, so a run that is not looked at row by row never pays for them;
:func:`stance_forces` derives a stride's ground force and hip torque
(``StepResult.grf``). Both use the stride kernel's formulas (:func:`._stance.grf_at`,
:func:`._flight.flight_point`) with the sines and cosines of
:func:`._sincos.sincos_array` (within 1 ulp of libm's, which the kernel uses), so the
two agree with each other bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import overload
from numba.np.unsafe.ndarray import to_fixed_tuple

from .._kernel_cache import check as _check_cache
from .._nrt import without_nrt
from ..model._pack import (
    NOUT,
    NP,
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
    P_NEXP,
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
    TR_T,
    TR_TAU,
    TR_X,
    TR_XD,
    TR_Y,
    TR_YD,
)
from ._flight import flight_leg_angle, flight_point, retraction_start
from ._rk import _INLINE, _JIT
from ._sincos import sincos_array
from ._stance import _com_velocity, grf_at, grf_of, hip_torque, leg_force, spring_energy
from ._stride import stride


@njit(**_INLINE)
def _energy(P, y, xd, yd, phid, l):
    """Total mechanical energy: kinetic + gravity + leg spring ``V`` [MgL]."""
    return _energy_of(P, y, xd, yd, phid, spring_energy(P, l))


@njit(**_INLINE)
def _energy_of(P, y, xd, yd, phid, v):
    """:func:`_energy` with the spring's energy ``v`` given."""
    return (0.5 * P[P_M] * (xd * xd + yd * yd) + 0.5 * P[P_J] * phid * phid
            + P[P_M] * P[P_G] * y + v)


@njit(**_INLINE)
def n_flight_samples(tf, dt, final):
    """Flight samples of a stride: ``dt, 2 dt, ...`` strictly before ``tf`` (those within
    1e-9 of it dropped: the next touch-down row follows), plus ``tf`` itself if ``final``."""
    n = max(0, int(math.ceil((tf - dt) / dt))) if tf > dt else 0
    if n > 0 and tf - (dt + (n - 1) * dt) < 1e-9:
        n -= 1
    return n + 1 if final else n


@njit(**_JIT)
def record_run(P, O, td, tx, th, first, last, close, dt, rows, starts, outs, info, pos):
    """Strides ``first .. last - 1`` of a run, sampled every ``dt`` into compact rows.

    Starts from the touch-down state ``td`` (7) at time ``pos[1]`` and writes
    from row ``pos[0]`` of ``rows`` (n x NREC), one row per trajectory sample:
    each stance's record rows as the stride kernel writes them (``REC_*``: time
    since touch-down and stance state, on the grid of
    :func:`._stride.stride`, touch-down and lift-off rows included), then
    one row per flight sample holding only its time since lift-off in ``REC_T``
    (``dt, 2 dt, ...``, and the touch-down instant closing the last stride if
    ``close``; otherwise the next stride's first row is that instant). Stride
    ``s`` fills ``starts[s]`` (its touch-down state), ``outs[s]``
    (:func:`._stride.stride`'s output) and ``info[s]`` (``RI_*``).
    :func:`fill_table` derives the trajectory's columns (forces included) from
    them when they are first read.

    The Runge-Kutta pair is ``O[O_METHOD]``. Returns the status of the last stride
    run (it stops at the first that is not OK), or ``RUN_FULL`` if the next stride's
    rows would not fit; then ``td``, ``pos = (row, t0, stride)`` say where to resume
    with more rows.
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
        status = stride(P, O, td, tx, th, rows[row:], dt, out)
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


@njit(**_INLINE)
def after_switch(t, tsw, at_steps):
    """Whether the record row at ``t`` holds a state the kernel integrated with the leg
    thrust's switched rest length (switch at ``tsw``; NaN without one: never). Rows
    recorded at each accepted step (``at_steps``) are so from ``t >= tsw`` on, the
    switch's own row included; grid rows only from ``t > tsw``: a grid row at ``tsw`` was
    sampled from the step that ends there, before the switch."""
    return t >= tsw if at_steps else t > tsw


#: :func:`fill_table`'s passes: they make no arrays, so they keep no reference counts
#: (:mod:`tslip._nrt`)
_FAST = without_nrt(**_JIT)

#: Rows :func:`fill_table` derives at a time (whole strides, this many or a stride's
#: more): a group's columns stay in the core's own (L2) cache from pass to pass.
GROUP_ROWS = 2048


def _param_tuple(P):  # noqa: N803 - the kernels' name
    """The packed parameters ``P`` as a tuple of ``NP`` floats: values, not memory, so a
    compiled loop knows that its stores leave them unchanged (:func:`_stance_columns`)."""
    return tuple(P)


@overload(_param_tuple, jit_options={"cache": True})
def _param_tuple_jit(P):  # noqa: N803
    return lambda P: to_fixed_tuple(P, NP)


@njit(**_INLINE)
def _fill(col, a, b, v):
    """``col[a:b] = v``, as a loop from 0 (no negative index for numba to wrap): packed stores."""
    c = col[a:b]
    for k in range(b - a):
        c[k] = v


@njit(**_FAST)
def _record_columns(P, rows, starts, outs, info, s0, s1, table, step, stance):
    """:func:`fill_table`'s first pass over strides ``s0 .. s1 - 1``: what needs no sine
    or cosine. Time, stride (into ``step``) and phase (into ``stance``); a stance row's
    state as recorded and its foot; a flight row's leg and pitch (eq. 2.17, ``phi``
    linear in time) and, for now, a foot at 0.0 (:func:`_flight_rows` writes it)."""
    for s in range(s0, s1):
        t0 = info[s, RI_T0]
        r0 = int(info[s, RI_ROW0])
        r1 = r0 + int(info[s, RI_NSTANCE])
        r2 = int(info[s, RI_ROW1])
        for k in range(r0, r1):
            table[TR_T, k] = t0 + rows[k, REC_T]
            table[TR_L, k] = rows[k, REC_L]
            table[TR_BETA, k] = rows[k, REC_BETA]
            table[TR_PHI, k] = rows[k, REC_PHI]
            table[TR_LD, k] = rows[k, REC_LD]
            table[TR_BETAD, k] = rows[k, REC_BETAD]
            table[TR_PHID, k] = rows[k, REC_PHID]
        _fill(step, r0, r2, s)
        _fill(stance, r0, r1, True)
        _fill(stance, r1, r2, False)
        _fill(table[TR_FOOTX], r0, r1, outs[s, OUT_XF])
        _fill(table[TR_FOOTX], r1, r2, 0.0)
        _fill(table[TR_FOOTY], r0, r1, starts[s, 6])
        _fill(table[TR_FOOTY], r1, r2, 0.0)
        _fill(table[TR_L], r1, r2, P[P_L0])
        _fill(table[TR_LD], r1, r2, 0.0)
        t_lo = t0 + outs[s, OUT_TS]
        lo = outs[s, OUT_LO:OUT_LO + 6]
        ta = retraction_start(P, lo[3])
        for k in range(r1, r2):
            tau = rows[k, REC_T]
            b, bd = flight_leg_angle(P, lo[4], lo[5], tau, ta)
            table[TR_T, k] = t_lo + tau
            table[TR_BETA, k] = b
            table[TR_PHI, k] = lo[4] + lo[5] * tau
            table[TR_BETAD, k] = bd
            table[TR_PHID, k] = lo[5]


@njit(**_FAST)
def _stance_columns(P, a, b, trig, table):
    """:func:`fill_table`'s third pass: rows ``a .. b - 1`` as stance rows, CoM and hip
    (eqs A.3-A.5) and ``alpha``, one column a loop; ``trig[:, k - a]`` holds row ``k``'s
    ``sin beta, cos beta, sin phi, cos phi`` (:func:`_flight_rows` redoes the flight
    rows). ``P`` is a tuple, so that its values are no memory the stores could change:
    each loop, storing one contiguous column, compiles to packed (SIMD) arithmetic. The
    loops run over views from row ``a`` on, so that their indices start at 0 (no
    negative index for numba to wrap)."""
    rp = P[P_R]
    m = b - a
    sb, cb, sp, cp = trig[0][:m], trig[1][:m], trig[2][:m], trig[3][:m]
    l, be, ph = table[TR_L][a:b], table[TR_BETA][a:b], table[TR_PHI][a:b]
    ld, bd, phd = table[TR_LD][a:b], table[TR_BETAD][a:b], table[TR_PHID][a:b]
    xf, h = table[TR_FOOTX][a:b], table[TR_FOOTY][a:b]
    x, y = table[TR_X][a:b], table[TR_Y][a:b]
    xd, yd = table[TR_XD][a:b], table[TR_YD][a:b]
    hip_x, hip_y = table[TR_HIPX][a:b], table[TR_HIPY][a:b]
    for k in range(m):
        hip_x[k] = xf[k] - l[k] * cb[k]
    for k in range(m):
        hip_y[k] = h[k] + l[k] * sb[k]
    for k in range(m):  # xf - l cb + rp sp
        x[k] = hip_x[k] + rp * sp[k]
    for k in range(m):  # h + l sb - rp cp
        y[k] = hip_y[k] - rp * cp[k]
    for k in range(m):
        xd[k] = _com_velocity(rp, l[k], sb[k], cb[k], sp[k], cp[k], ld[k], bd[k], phd[k])[0]
    for k in range(m):
        yd[k] = _com_velocity(rp, l[k], sb[k], cb[k], sp[k], cp[k], ld[k], bd[k], phd[k])[1]
    col = table[TR_ALPHA][a:b]
    for k in range(m):
        col[k] = be[k] + ph[k]


@njit(**_INLINE)
def _spring_loops(P, l, ld, fl, v):
    """:func:`_spring_columns`'s loops: leg force ``fl`` (eq. 2.1) and spring energy ``v``
    of the legs ``l``, ``ld``."""
    for k in range(l.shape[0]):
        fl[k] = leg_force(P, l[k], ld[k])
    for k in range(l.shape[0]):
        v[k] = spring_energy(P, l[k])


@njit(**_FAST)
def _spring_columns(P, a, b, trig, table):
    """:func:`fill_table`'s fourth pass: the leg force and the spring's energy of rows
    ``a .. b - 1`` as stance rows, into ``trig[4]`` and ``trig[5]``. For the linear
    spring (``n = 1``), known as such in its branch, the loops compile without the power
    law's ``pow`` and vectorise (the table took three times as long without)."""
    m = b - a
    l, ld, fl, v = table[TR_L][a:b], table[TR_LD][a:b], trig[4][:m], trig[5][:m]
    if P[P_NEXP] == 1.0:
        _spring_loops(P, l, ld, fl, v)
    else:
        _spring_loops(P, l, ld, fl, v)


@njit(**_FAST)
def _force_columns(P, a, b, trig, table):
    """:func:`fill_table`'s fifth pass (see :func:`_stance_columns`): the ground force,
    hip torque (eqs 2.5-2.6) and energy of rows ``a .. b - 1`` as stance rows, from the
    leg force and spring energy in ``trig[4]``, ``trig[5]`` (:func:`_spring_columns`)."""
    m = b - a
    sb, cb, fl, v = trig[0][:m], trig[1][:m], trig[4][:m], trig[5][:m]
    l, ph = table[TR_L][a:b], table[TR_PHI][a:b]
    bd, phd = table[TR_BETAD][a:b], table[TR_PHID][a:b]
    y, xd, yd = table[TR_Y][a:b], table[TR_XD][a:b], table[TR_YD][a:b]
    tau = table[TR_TAU][a:b]
    for k in range(m):
        tau[k] = hip_torque(P, ph[k], bd[k], phd[k])
    col = table[TR_FX][a:b]
    for k in range(m):
        col[k] = grf_of(fl[k], tau[k], l[k], sb[k], cb[k])[0]
    col = table[TR_FY][a:b]
    for k in range(m):
        col[k] = grf_of(fl[k], tau[k], l[k], sb[k], cb[k])[1]
    col = table[TR_ENERGY][a:b]
    for k in range(m):
        col[k] = _energy_of(P, y[k], xd[k], yd[k], phd[k], v[k])


@njit(**_FAST)
def _flight_rows(P, Pw, rows, outs, info, s0, s1, a, trig, table):
    """:func:`fill_table`'s last pass over strides ``s0 .. s1 - 1`` (first row ``a``): the
    flight rows in closed form (:func:`._flight.flight_point`, eq. 2.7), and a thrust's
    stance rows after its switch (:func:`after_switch`) again with the switched
    parameters ``Pw``."""
    l0 = P[P_L0]
    for s in range(s0, s1):
        r0 = int(info[s, RI_ROW0])
        r1 = r0 + int(info[s, RI_NSTANCE])
        tsw = outs[s, OUT_TSW]  # NaN without a switch: no row is after it
        if tsw == tsw:
            for k in range(r0, r1):
                if after_switch(rows[k, REC_T], tsw, False):
                    l, ph, phd = table[TR_L, k], table[TR_PHI, k], table[TR_PHID, k]
                    table[TR_FX, k], table[TR_FY, k], table[TR_TAU, k] = grf_at(
                        Pw, l, ph, table[TR_LD, k], table[TR_BETAD, k], phd, trig[0, k - a],
                        trig[1, k - a])
                    table[TR_ENERGY, k] = _energy(Pw, table[TR_Y, k], table[TR_XD, k],
                                                  table[TR_YD, k], phd, l)
        lo = outs[s, OUT_LO:OUT_LO + 6]
        for k in range(r1, int(info[s, RI_ROW1])):
            i = k - a
            x, y, yd, hip_x, hip_y, foot_x, foot_y = flight_point(
                P, lo, rows[k, REC_T], trig[2, i], trig[3, i], trig[0, i], trig[1, i])
            table[TR_X, k] = x
            table[TR_Y, k] = y
            table[TR_XD, k] = lo[2]
            table[TR_YD, k] = yd
            table[TR_FOOTX, k] = foot_x
            table[TR_FOOTY, k] = foot_y
            table[TR_HIPX, k] = hip_x
            table[TR_HIPY, k] = hip_y
            table[TR_FX, k] = 0.0
            table[TR_FY, k] = 0.0
            table[TR_TAU, k] = 0.0
            table[TR_ENERGY, k] = _energy(P, y, lo[2], yd, lo[5], l0)


@njit(**_JIT)
def fill_table(P, rows, starts, outs, info, n, table, step, stance):
    """The trajectory columns (``TR_*``, one row of ``table`` each) of a recorded run.

    ``rows``, ``starts``, ``outs`` and ``info`` hold strides ``0 .. n - 1`` as
    :func:`record_run` wrote them; ``table`` is
    ``NTRAJ x rows`` (column-major: a column of the trajectory is a row here). The
    stride and phase columns go to ``step`` (integers) and ``stance`` (booleans), as
    the trajectory's frame types them; ``table``'s ``TR_STEP`` and ``TR_STANCE`` rows
    are left as they are (a frame never reads them, so their pages are never touched).
    Stance rows come from the record rows by eqs A.3-A.5 (their forces by eqs
    2.5-2.6), flight rows from the lift-off state in closed form (eq. 2.7). A stance
    row after the leg thrust's switch (``OUT_TSW``) takes the switched rest length,
    as the stride kernel's grid did (:func:`stance_forces`).

    Column by column where it can, a group of strides (:data:`GROUP_ROWS`) at a time,
    so that most of the work compiles to packed (SIMD) arithmetic and stores (row by
    row, a row's 22 scalar stores and libm's ``sincos`` cost more than its arithmetic):
    the columns that need no trigonometry (:func:`_record_columns`), the sines and
    cosines of every ``beta`` and ``phi`` (:func:`._sincos.sincos_array`, within 1 ulp
    of libm), every row as a stance row (:func:`_stance_columns`, :func:`_spring_columns`,
    :func:`_force_columns`), then the flight rows and a thrust's rows after its switch
    (:func:`_flight_rows`). Each value is computed with the stride kernel's operations
    in its order; only the sines and cosines are not libm's.
    """
    if n == 0:
        return
    Pw = P.copy()  # the switched parameters of a thrust's stance rows
    Pw[P_THRUST] = -P[P_THRUST]
    pt, pw = _param_tuple(P), _param_tuple(Pw)
    most = 0  # rows of the longest stride: a group has fewer than GROUP_ROWS + most
    for s in range(n):
        most = max(most, int(info[s, RI_ROW1] - info[s, RI_ROW0]))
    # sin beta, cos beta, sin phi, cos phi, leg force, spring energy of a group's rows
    trig = np.empty((6, GROUP_ROWS + most))
    # not the literal 0: typing the loop's first pass with Literal[int](0) compiled
    # _record_columns and _flight_rows a second time, for that literal (a fifth of this
    # kernel's compile time; the calls run the int64 ones either way)
    s0 = np.int64(0)
    while s0 < n:
        a = int(info[s0, RI_ROW0])
        s1 = s0 + 1
        while s1 < n and info[s1, RI_ROW0] - a < GROUP_ROWS:
            s1 += 1
        b = int(info[s1 - 1, RI_ROW1])
        _record_columns(pt, rows, starts, outs, info, s0, s1, table, step, stance)
        sincos_array(table[TR_BETA, a:b], trig[0, :b - a], trig[1, :b - a])
        sincos_array(table[TR_PHI, a:b], trig[2, :b - a], trig[3, :b - a])
        _stance_columns(pt, a, b, trig, table)
        _spring_columns(pt, a, b, trig, table)
        _force_columns(pt, a, b, trig, table)
        _flight_rows(pt, pw, rows, outs, info, s0, s1, a, trig, table)
        s0 = s1


@njit(**_JIT)
def stance_forces(P, rec, tsw, at_steps, grf):
    """A stance's ground force and hip torque from its record rows ``rec`` (n x NREC):
    ``grf`` (n x 4) receives ``t, F_x, F_y, tau`` (``StepResult.grf``) by the stride
    kernel's formula (:func:`._stance.grf_at`) with the sines and cosines of
    :func:`._sincos.sincos_array`, as :func:`fill_table` computes them: a simulated
    stride's ``grf`` is its rows' ``Fx, Fy, tau``, bit for bit.

    With a leg thrust the kernel ran on the switched rest length from the switch on
    (``tsw``, its ``OUT_TSW``): which rows that covers depends on how they were recorded,
    at each accepted step (``at_steps``, :func:`tslip.step`) or on the grid
    (``tslip.simulate``, as :func:`fill_table` reads them): :func:`after_switch`.
    """
    Pw = P.copy()  # the switched parameters of a thrust's rows after the switch
    Pw[P_THRUST] = -P[P_THRUST]
    n = rec.shape[0]
    trig = np.empty((3, n))  # beta, its sine and cosine
    for k in range(n):
        trig[0, k] = rec[k, REC_BETA]
    sincos_array(trig[0], trig[1], trig[2])
    for k in range(n):
        r = rec[k]
        t = r[REC_T]
        Pk = Pw if after_switch(t, tsw, at_steps) else P
        grf[k, 0] = t
        grf[k, 1], grf[k, 2], grf[k, 3] = grf_at(Pk, r[REC_L], r[REC_PHI], r[REC_LD],
                                                 r[REC_BETAD], r[REC_PHID], trig[1, k],
                                                 trig[2, k])


# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(fill_table, __file__)
