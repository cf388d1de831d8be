"""The one embedded Runge-Kutta core of the kernels: tableaus, stages, error, dense output, events.

Private. Two explicit pairs (Hairer, Norsett & Wanner, *Solving ODEs I*, II.5 and II.6):

* ``dopri5``: Dormand-Prince 5(4), 6 stages + FSAL, 4th-order continuous
  extension (dopri5 ``contd5``);
* ``dop853``: Dormand-Prince 8(5,3), 12 stages + FSAL, Hairer's combined
  5th/3rd-order error estimate and 7th-order dense output (3 extra stages).

Each tableau is padded into one row of the ``*_TAB`` arrays below (index =
method code of :mod:`tslip.model._pack`), so every routine here is written
once for both methods and takes the method as a value: the TSLIP's kernels pass
it at run time (``O[O_METHOD]``: each compiles once for both pairs), the biped's
as a constant of each per-method copy. The error norm and the dense output branch
once on the pair to a copy with its sizes and coefficients constants, which the
compiler unrolls with the coefficients folded in (a TSLIP stride's instructions: see
:mod:`tslip.simulation._stride`).

Numba cannot cache a kernel that receives its right-hand side as a function
argument (the cache key is the dispatcher type, which differs per process), so
the right-hand side never enters this module. A model's stepper is the short
loop below, with its own ``rhs`` in place of ``f``; all arithmetic on the
stages is here::

    ns = n_stages(method)
    for s in range(1, ns):                      # K[0] = f(t, y) on entry
        stage_state(method, n, y, h, K, s, ytmp)
        f(t + stage_c(method, s) * h, ytmp, K[s])
    stage_state(method, n, y, h, K, ns, ynew)   # the solution (A[ns] = B)
    f(t + h, ynew, K[ns])                       # FSAL: next step's K[0]
    err = error_norm(method, n, y, ynew, h, K, rtol, atol)

Dense output likewise evaluates ``n_extra(method)`` stages ``ns + 1 ...`` with
:func:`stage_state` before :func:`dense_coeffs`. Events are located on the
dense output with the Illinois method driven by the caller
(:func:`root_start`, :func:`root_guess`, :func:`root_update`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel_cache import check as _check_cache
from ..model._pack import M_DOP853, M_DOPRI5

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}
# the per-step helpers are inlined into the caller's stage loop (numba IR
# inlining); the method is a run-time value in the TSLIP's kernels (one kernel for
# both pairs) and a compile-time constant in the biped's
_INLINE = dict(_JIT, inline="always")

#: rows of the stage array ``K`` and of the dense-output array ``R`` that fit both methods
NK = 16
NR = 8

# ---------------------------------------------------------------------------
# Dormand-Prince 5(4) (Dormand & Prince 1980; dopri5)
# ---------------------------------------------------------------------------
_DP5_C = (0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0)
_DP5_A = (
    (),
    (1.0 / 5.0,),
    (3.0 / 40.0, 9.0 / 40.0),
    (44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0),
    (19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0),
    (9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0),
    # the 5th-order weights B (FSAL row)
    (35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0),
)
# B - B_hat (4th order), on the stages and the FSAL row
_DP5_E = (71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0,
          22.0 / 525.0, -1.0 / 40.0)
# the 5th coefficient row of contd5 (the first four follow from y, ynew, f, fnew)
_DP5_D = ((-12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
           -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
           -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0),)

# ---------------------------------------------------------------------------
# Dormand-Prince 8(5,3) (Hairer's dop853.f; Prince & Dormand 1981)
# ---------------------------------------------------------------------------
_DOP853_C = (
    0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510, 0.281649658092772603273242802490,
    0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692,
    0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0, 1.0,
    0.1, 0.2, 0.777777777777777777777777777778,
)
# sparse rows {column: value}; row 12 holds the 8th-order weights B (FSAL),
# rows 13-15 the extra stages of the dense output
_DOP853_A = {
    1: {0: 5.26001519587677318785587544488e-2},
    2: {0: 1.97250569845378994544595329183e-2, 1: 5.91751709536136983633785987549e-2},
    3: {0: 2.95875854768068491816892993775e-2, 2: 8.87627564304205475450678981324e-2},
    4: {0: 2.41365134159266685502369798665e-1, 2: -8.84549479328286085344864962717e-1,
        3: 9.24834003261792003115737966543e-1},
    5: {0: 3.7037037037037037037037037037e-2, 3: 1.70828608729473871279604482173e-1,
        4: 1.25467687566822425016691814123e-1},
    6: {0: 3.7109375e-2, 3: 1.70252211019544039314978060272e-1,
        4: 6.02165389804559606850219397283e-2, 5: -1.7578125e-2},
    7: {0: 3.70920001185047927108779319836e-2, 3: 1.70383925712239993810214054705e-1,
        4: 1.07262030446373284651809199168e-1, 5: -1.53194377486244017527936158236e-2,
        6: 8.27378916381402288758473766002e-3},
    8: {0: 6.24110958716075717114429577812e-1, 3: -3.36089262944694129406857109825,
        4: -8.68219346841726006818189891453e-1, 5: 2.75920996994467083049415600797e1,
        6: 2.01540675504778934086186788979e1, 7: -4.34898841810699588477366255144e1},
    9: {0: 4.77662536438264365890433908527e-1, 3: -2.48811461997166764192642586468,
        4: -5.90290826836842996371446475743e-1, 5: 2.12300514481811942347288949897e1,
        6: 1.52792336328824235832596922938e1, 7: -3.32882109689848629194453265587e1,
        8: -2.03312017085086261358222928593e-2},
    10: {0: -9.3714243008598732571704021658e-1, 3: 5.18637242884406370830023853209,
         4: 1.09143734899672957818500254654, 5: -8.14978701074692612513997267357,
         6: -1.85200656599969598641566180701e1, 7: 2.27394870993505042818970056734e1,
         8: 2.49360555267965238987089396762, 9: -3.0467644718982195003823669022},
    11: {0: 2.27331014751653820792359768449, 3: -1.05344954667372501984066689879e1,
         4: -2.00087205822486249909675718444, 5: -1.79589318631187989172765950534e1,
         6: 2.79488845294199600508499808837e1, 7: -2.85899827713502369474065508674,
         8: -8.87285693353062954433549289258, 9: 1.23605671757943030647266201528e1,
         10: 6.43392746015763530355970484046e-1},
    12: {0: 5.42937341165687622380535766363e-2, 5: 4.45031289275240888144113950566,
         6: 1.89151789931450038304281599044, 7: -5.8012039600105847814672114227,
         8: 3.1116436695781989440891606237e-1, 9: -1.52160949662516078556178806805e-1,
         10: 2.01365400804030348374776537501e-1, 11: 4.47106157277725905176885569043e-2},
    13: {0: 5.61675022830479523392909219681e-2, 6: 2.53500210216624811088794765333e-1,
         7: -2.46239037470802489917441475441e-1, 8: -1.24191423263816360469010140626e-1,
         9: 1.5329179827876569731206322685e-1, 10: 8.20105229563468988491666602057e-3,
         11: 7.56789766054569976138603589584e-3, 12: -8.298e-3},
    14: {0: 3.18346481635021405060768473261e-2, 5: 2.83009096723667755288322961402e-2,
         6: 5.35419883074385676223797384372e-2, 7: -5.49237485713909884646569340306e-2,
         10: -1.08347328697249322858509316994e-4, 11: 3.82571090835658412954920192323e-4,
         12: -3.40465008687404560802977114492e-4, 13: 1.41312443674632500278074618366e-1},
    15: {0: -4.28896301583791923408573538692e-1, 5: -4.69762141536116384314449447206,
         6: 7.68342119606259904184240953878, 7: 4.06898981839711007970213554331,
         8: 3.56727187455281109270669543021e-1, 12: -1.39902416515901462129418009734e-3,
         13: 2.9475147891527723389556272149, 14: -9.15095847217987001081870187138},
}
# 5th-order error coefficients, and B minus the 3rd-order weights
_DOP853_E5 = {0: 0.1312004499419488073250102996e-1, 5: -0.1225156446376204440720569753e+1,
              6: -0.4957589496572501915214079952, 7: 0.1664377182454986536961530415e+1,
              8: -0.3503288487499736816886487290, 9: 0.3341791187130174790297318841,
              10: 0.8192320648511571246570742613e-1, 11: -0.2235530786388629525884427845e-1}
_DOP853_BHH = {0: 0.244094488188976377952755905512, 8: 0.733846688281611857341361741547,
               11: 0.220588235294117647058823529412e-1}
# rows 4-7 of the 7th-order dense output (the first three follow from y, ynew, f, fnew)
_DOP853_D = (
    {0: -0.84289382761090128651353491142e+1, 5: 0.56671495351937776962531783590,
     6: -0.30689499459498916912797304727e+1, 7: 0.23846676565120698287728149680e+1,
     8: 0.21170345824450282767155149946e+1, 9: -0.87139158377797299206789907490,
     10: 0.22404374302607882758541771650e+1, 11: 0.63157877876946881815570249290,
     12: -0.88990336451333310820698117400e-1, 13: 0.18148505520854727256656404962e+2,
     14: -0.91946323924783554000451984436e+1, 15: -0.44360363875948939664310572000e+1},
    {0: 0.10427508642579134603413151009e+2, 5: 0.24228349177525818288430175319e+3,
     6: 0.16520045171727028198505394887e+3, 7: -0.37454675472269020279518312152e+3,
     8: -0.22113666853125306036270938578e+2, 9: 0.77334326684722638389603898808e+1,
     10: -0.30674084731089398182061213626e+2, 11: -0.93321305264302278729567221706e+1,
     12: 0.15697238121770843886131091075e+2, 13: -0.31139403219565177677282850411e+2,
     14: -0.93529243588444783865713862664e+1, 15: 0.35816841486394083752465898540e+2},
    {0: 0.19985053242002433820987653617e+2, 5: -0.38703730874935176555105901742e+3,
     6: -0.18917813819516756882830838328e+3, 7: 0.52780815920542364900561016686e+3,
     8: -0.11573902539959630126141871134e+2, 9: 0.68812326946963000169666922661e+1,
     10: -0.10006050966910838403183860980e+1, 11: 0.77771377980534432092869265740,
     12: -0.27782057523535084065932004339e+1, 13: -0.60196695231264120758267380846e+2,
     14: 0.84320405506677161018159903784e+2, 15: 0.11992291136182789328035130030e+2},
    {0: -0.25693933462703749003312586129e+2, 5: -0.15418974869023643374053993627e+3,
     6: -0.23152937917604549567536039109e+3, 7: 0.35763911791061412378285349910e+3,
     8: 0.93405324183624310003907691704e+2, 9: -0.37458323136451633156875139351e+2,
     10: 0.10409964950896230045147246184e+3, 11: 0.29840293426660503123344363579e+2,
     12: -0.43533456590011143754432175058e+2, 13: 0.96324553959188282948394950600e+2,
     14: -0.39177261675615439165231486172e+2, 15: -0.14972683625798562581422125276e+3},
)


def _tables():
    """Both tableaus padded into arrays indexed ``[method, ...]``."""
    C = np.zeros((2, NK))
    A = np.zeros((2, NK, NK))
    E = np.zeros((2, NK))  # error weights (dopri5: B - B_hat; dop853: 5th-order estimate)
    E3 = np.zeros((2, NK))  # dop853 only: B - B_3 (3rd-order estimate)
    D = np.zeros((2, NR - 4, NK))  # dense rows 4 ... (after y, dy, and two Hermite rows)
    C[M_DOPRI5, :7] = _DP5_C
    for s, row in enumerate(_DP5_A):
        A[M_DOPRI5, s, : len(row)] = row
    E[M_DOPRI5, :7] = _DP5_E
    D[M_DOPRI5, 0, :7] = _DP5_D[0]
    C[M_DOP853] = _DOP853_C
    for s, row in _DOP853_A.items():
        for j, v in row.items():
            A[M_DOP853, s, j] = v
    for j, v in _DOP853_E5.items():
        E[M_DOP853, j] = v
    E3[M_DOP853, :12] = A[M_DOP853, 12, :12]
    for j, v in _DOP853_BHH.items():
        E3[M_DOP853, j] -= v
    for k, row in enumerate(_DOP853_D):
        for j, v in row.items():
            D[M_DOP853, k, j] = v
    return C, A, E, E3, D


C_TAB, A_TAB, E_TAB, E3_TAB, D_TAB = _tables()
#: stages before the FSAL row, extra dense-output stages, dense rows, order
NSTAGES = np.array([6, 12], dtype=np.int64)
NEXTRA = np.array([0, 3], dtype=np.int64)
NDENSE = np.array([5, 8], dtype=np.int64)
ORDER = np.array([5.0, 8.0])
#: step-size exponent -1/(q+1), q the order of the error estimator (4 and 7)
ERR_EXP = np.array([-0.2, -0.125])
# the sizes error_norm, dense_coeffs and dense_eval write out as constants, per pair
assert (tuple(NSTAGES), tuple(NEXTRA), tuple(NDENSE)) == ((6, 12), (0, 3), (5, 8))
assert (M_DOPRI5, M_DOP853) == (0, 1)
#: The safety factor on the step the error estimate asks for: aims below it, so that the
#: next step is rarely rejected (Hairer's dopri5.f and dop853.f, ``safe``)
SAFETY = 0.9
#: The smallest step-size factor: a step shrinks at most fivefold at once, however large
#: its error (dopri5.f's default ``fac1``; an error estimate that far off says little)
FAC_MIN = 0.2


@njit(**_INLINE)
def n_stages(method):
    """Stages per step before the FSAL evaluation (6 or 12)."""
    return NSTAGES[method]


@njit(**_INLINE)
def n_extra(method):
    """Extra right-hand sides the dense output needs (0 or 3)."""
    return NEXTRA[method]


@njit(**_INLINE)
def stage_c(method, s):
    """Node ``c_s`` of stage ``s`` (the stage time is ``t + c_s h``)."""
    return C_TAB[method, s]


@njit(**_INLINE)
def stage_state(method, n, y, h, K, s, out):
    """``out = y + h sum_{j<s} a_sj K[j]`` (``n`` components): the input of stage ``s``.

    With ``s = n_stages(method)`` (the FSAL row, whose coefficients are the
    weights ``b``) this is the new solution.
    """
    a = A_TAB[method, s]
    for i in range(n):
        out[i] = 0.0
    for j in range(s):  # row by row (contiguous), skipping zeros: same sums as per component
        aj = a[j]
        if aj != 0.0:
            for i in range(n):
                out[i] += aj * K[j, i]
    for i in range(n):
        out[i] = y[i] + h * out[i]


@njit(**_INLINE)
def error_norm(method, n, y, ynew, h, K, rtol, atol):
    """Error of the step in units of the tolerance (accept if <= 1).

    dopri5: Hairer's RMS norm of ``h sum (b_j - bhat_j) K[j]``. dop853: the
    combined estimate of dop853.f, ``|h| err5^2 / sqrt(n (err5^2 + 0.01 err3^2))``
    with RMS-free sums ``err5``, ``err3`` of the 5th- and 3rd-order estimates.
    Scales ``atol + rtol max(|y|, |ynew|)``. ``K`` holds the FSAL row.

    One branch on the pair, then each pair's sums with its weights and stage count
    as constants (:func:`_error_dopri5`, :func:`_error_dop853`), so the compiler unrolls
    them with the weights folded in even where ``method`` is a run-time value.
    """
    if method == M_DOPRI5:
        return _error_dopri5(n, y, ynew, h, K, rtol, atol)
    return _error_dop853(n, y, ynew, h, K, rtol, atol)


@njit(**_INLINE)
def _error_dopri5(n, y, ynew, h, K, rtol, atol):
    """:func:`error_norm` of dopri5 (its 7 weights ``b - bhat`` constants)."""
    e = E_TAB[M_DOPRI5]
    s = 0.0
    for i in range(n):
        acc = 0.0
        for j in range(7):
            acc += e[j] * K[j, i]
        sk = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        s += (h * acc / sk) ** 2
    return math.sqrt(s / n)


@njit(**_INLINE)
def _error_dop853(n, y, ynew, h, K, rtol, atol):
    """:func:`error_norm` of dop853 (its 13 weights of each estimate constants)."""
    e = E_TAB[M_DOP853]
    e3 = E3_TAB[M_DOP853]
    s5 = 0.0
    s3 = 0.0
    for i in range(n):
        a5 = 0.0
        a3 = 0.0
        for j in range(13):
            a5 += e[j] * K[j, i]
            a3 += e3[j] * K[j, i]
        sk = atol + rtol * max(abs(y[i]), abs(ynew[i]))
        s5 += (a5 / sk) ** 2
        s3 += (a3 / sk) ** 2
    deno = s5 + 0.01 * s3
    if deno <= 0.0:
        deno = 1.0
    return abs(h) * s5 / math.sqrt(n * deno)


@njit(**_INLINE)
def step_factor(method, err, fac_max):
    """Step-size factor ``SAFETY err^(-1/(q+1))`` clipped to ``[FAC_MIN, fac_max]``."""
    if err <= 0.0:
        return fac_max
    return min(fac_max, max(FAC_MIN, SAFETY * err ** ERR_EXP[method]))


@njit(**_INLINE)
def initial_probe(y, f0, rtol, atol, out):
    """First half of the starting step (Hairer, Norsett & Wanner, II.4).

    Returns the trial step ``h0`` and ``|f0|``; ``out = y + h0 f0`` is where the
    caller evaluates ``f1`` for :func:`initial_step`.
    """
    n = y.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sk = atol + rtol * abs(y[i])
        d0 += (y[i] / sk) ** 2
        d1 += (f0[i] / sk) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    for i in range(n):
        out[i] = y[i] + h0 * f0[i]
    return h0, d1


@njit(**_INLINE)
def initial_step(method, y, f0, f1, h0, d1, rtol, atol):
    """Starting step from the probe ``f1 = f(y + h0 f0)``: ``(0.01 / |f'|)^(1/p)``."""
    n = y.shape[0]
    d2 = 0.0
    for i in range(n):
        sk = atol + rtol * abs(y[i])
        d2 += ((f1[i] - f0[i]) / sk) ** 2
    d2 = math.sqrt(d2 / n) / h0
    dm = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if dm <= 1e-15 else (0.01 / dm) ** (1.0 / ORDER[method])
    return min(100.0 * h0, h1)


@njit(**_JIT)
def dense_coeffs(method, y, ynew, h, K, R):
    """Coefficients of the continuous extension of the step ``y -> ynew``.

    ``K`` must hold the FSAL row and, for dop853, the ``n_extra`` stages after
    it. Rows: ``y``, ``dy``, ``h f0 - dy``, ``dy - h f1 - (h f0 - dy)``, then
    ``h sum_j d_kj K[j]`` (dopri5 ``contd5``: one row; dop853: four). One branch
    on the pair, each pair's sizes and rows constants (:func:`_dense_coeffs_of`).
    """
    if method == M_DOPRI5:
        _dense_coeffs_of(M_DOPRI5, 6, 5, 7, y, ynew, h, K, R)
    else:
        _dense_coeffs_of(M_DOP853, 12, 8, 16, y, ynew, h, K, R)


@njit(**_INLINE)
def _dense_coeffs_of(method, ns, nd, nk, y, ynew, h, K, R):
    """:func:`dense_coeffs` of the pair ``method`` with ``ns`` stages, ``nd`` dense rows,
    ``nk`` stages in its sums: called with constants, so that its loops unroll with the
    coefficients folded in (and their zero tests gone)."""
    for i in range(y.shape[0]):
        ydiff = ynew[i] - y[i]
        bspl = h * K[0, i] - ydiff
        R[0, i] = y[i]
        R[1, i] = ydiff
        R[2, i] = bspl
        R[3, i] = ydiff - h * K[ns, i] - bspl
        for k in range(nd - 4):
            d = D_TAB[method, k]
            acc = 0.0
            for j in range(nk):
                if d[j] != 0.0:
                    acc += d[j] * K[j, i]
            R[4 + k, i] = h * acc


@njit(**_JIT)
def dense_eval(method, R, theta, out):
    """The continuous extension at ``theta`` in [0, 1] of the step.

    ``R0 + th (R1 + (1 - th) (R2 + th (R3 + (1 - th) (R4 + ...))))``. One branch on
    the pair, its number of rows a constant (:func:`_dense_eval_of`).
    """
    if method == M_DOPRI5:
        _dense_eval_of(5, R, theta, out)
    else:
        _dense_eval_of(8, R, theta, out)


@njit(**_INLINE)
def _dense_eval_of(nd, R, theta, out):
    """:func:`dense_eval` with ``nd`` rows (a constant: the loop over them unrolls)."""
    t1 = 1.0 - theta
    for i in range(out.shape[0]):
        acc = R[nd - 1, i]
        for k in range(nd - 2, -1, -1):
            acc = R[k, i] + (theta if k % 2 == 0 else t1) * acc
        out[i] = acc


# ---------------------------------------------------------------------------
# Event location: Illinois (modified regula falsi) on the dense output
# ---------------------------------------------------------------------------
# State ``st = [a, b, g(a), g(b), side]`` with g(a) > 0 >= g(b); the caller
# evaluates the event function at each guess:
#
#     root_start(st, g_old, g_new)
#     for _ in range(100):
#         c = root_guess(st)
#         dense_eval(method, R, c, ytmp); gc = event(ytmp)
#         if root_update(st, c, gc, tol):
#             break
#     theta = st[1]   # the earliest theta known to be at or past the crossing


@njit(**_JIT)
def root_start(st, g_lo, g_hi):
    """Bracket ``[0, 1]`` with ``g(0) = g_lo > 0 >= g_hi = g(1)``."""
    st[0] = 0.0
    st[1] = 1.0
    st[2] = g_lo
    st[3] = g_hi
    st[4] = 0.0


@njit(**_JIT)
def root_guess(st):
    """Next trial point: the secant of the bracket (its midpoint if degenerate)."""
    a, b, fa, fb = st[0], st[1], st[2], st[3]
    c = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
    if not (a < c < b):
        c = 0.5 * (a + b)
    return c


@njit(**_JIT)
def root_update(st, c, fc, tol):
    """Shrink the bracket with ``g(c) = fc``; halve the stale end's value
    (Illinois). Returns True once the bracket is narrower than ``tol``."""
    if fc > 0.0:
        st[0] = c
        st[2] = fc
        if st[4] == -1.0:
            st[3] *= 0.5
        st[4] = -1.0
    else:
        st[1] = c
        st[3] = fc
        if st[4] == 1.0:
            st[2] *= 0.5
        st[4] = 1.0
    return st[1] - st[0] < tol


# ---------------------------------------------------------------------------
# Events that start at their zero. An event fires on a crossing from > 0 to <= 0
# between a step's ends. A phase can start with an event function at its zero: a
# lift-off function at touch-down, where the leg or foot force is exactly 0 (the
# TSLIP's undamped leg at rest length), or a few ulps from it (the biped's foot,
# located to 1e-13 in time). If the phase is a hump of that function shorter
# than the first step, the step ends with it at or below zero again, and the
# event is never seen (the stance is lost: a false fall) or is located at the
# start. So the first accepted step of a phase that ends with an event function
# at or below zero is checked: if that function left its zero upward at the
# phase's start (:func:`left_zero_upward`, from its values at ``y + ZERO_PROBE h
# f(y)`` that each model computes with its own event functions), the step jumped
# a whole hump (:func:`jumped_hump`), and is retried HUMP_SHRINK times as long,
# until it ends inside the hump, where the event is armed. The TSLIP reads the
# probe once at a stance's start, and only if an event starts at or below zero;
# the biped only when a first step ends with a function at or below zero.
# ---------------------------------------------------------------------------

#: Where an event function is probed for how it leaves its start: this fraction of the
#: step (a first-order probe; only a hump shorter than it escapes).
ZERO_PROBE = 1e-6
#: The factor by which a first step that jumped a whole hump (:func:`jumped_hump`) is
#: retried shorter, as a step whose stages were not finite is.
HUMP_SHRINK = 0.1


@njit(**_INLINE)
def left_zero_upward(g_start, g_probe):
    """Whether an event function with value ``g_start`` at a phase's start and ``g_probe``
    at the probe (``y + ZERO_PROBE h f(y)``) left its zero upward at the start, or within
    the probe's length before it: ``g_probe > 0`` and ``g_start <= g_probe - g_start`` (the
    linear extrapolation back from the probe reaches zero no earlier than one probe length
    before the start)."""
    return g_probe > 0.0 and 2.0 * g_start <= g_probe


@njit(**_INLINE)
def jumped_hump(g_start, g_end, g_probe):
    """Whether a phase's first step, ending at ``g_end``, jumped a whole hump of an event
    function that :func:`left_zero_upward` (``g_start``, ``g_probe``): it ends at or below
    zero again."""
    return g_end <= 0.0 and left_zero_upward(g_start, g_probe)


@njit(**_INLINE)
def all_finite(n, y):
    """Whether the first ``n`` components of ``y`` are finite (an accepted step's end)."""
    for i in range(n):
        if not math.isfinite(y[i]):
            return False
    return True


@njit(**_INLINE)
def accept_step(method, n, y, ynew, K):
    """Move a loop of ``n`` states on to its accepted step's end: ``y = ynew`` and the
    step's last stage as the next step's first (FSAL). The TSLIP's stride has its own
    twin with the event values (``_stride.advance``); the spatial loops call this."""
    ns = n_stages(method)
    for i in range(n):
        y[i] = ynew[i]
        K[0, i] = K[ns, i]


# ---------------------------------------------------------------------------
# The same routines inlined: the TSLIP's stride kernels call these twins, so a
# stride compiles as one function (each separately compiled callee costs a
# compile and a re-optimisation in every caller); the biped calls the ones above
# ---------------------------------------------------------------------------


def _inlined(kernel):
    return njit(**_INLINE)(getattr(kernel, "py_func", kernel))  # no py_func without the JIT


dense_coeffs_inline = _inlined(dense_coeffs)
dense_eval_inline = _inlined(dense_eval)
root_start_inline = _inlined(root_start)
root_guess_inline = _inlined(root_guess)
root_update_inline = _inlined(root_update)

# numba does not notice when a kernel called from another file changes; drop
# cached kernels compiled against other sources (see tslip._kernel_cache).
_check_cache(root_update, __file__)
