"""Public biped simulation API: runs, one stride, typed results.

Validates inputs, calls :func:`._kernels.run`, and maps its flat arrays and
status to a :class:`Trajectory` with a shared :class:`tslip.Status`. A stride
(a "step" of the shared vocabulary, docs/model.md) is right-foot touch-down to
the next right-foot touch-down (Section E.2.5).

Counting strides
----------------
The kernels stop after ``n_steps`` right-foot *contact events*, and the
ground model (eqs E.23-E.24) also registers scuffs: a swinging foot that
brushes the ground for a fraction of a millisecond (the foot mass on the
ground damper relaxes in ``m_f / c_z = 1e-3`` g^-1/2 L^1/2). Such a contact
carries no weight and is not a step. :func:`count_strides` therefore counts
only right touch-downs whose contact lasts at least ``min_contact``; by
default (:func:`default_min_contact`) a tenth of the controller's nominal
stance ``d T`` (eq. E.29), 0.081 g^-1/2 L^1/2 for Table E.4: 80 times the
foot's contact time constant, and a seventh of the ~0.57 the runner's real
stances last. On the Table E.2 run the count is the same for any minimum
between 0.001 and 0.15.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .._checks import check_fields
from .._renamed import accepts_n_strides, module_getattr, warn_renamed
from .._results import Result, frame, with_units
from ..model._pack import METHODS
from ..simulation.result import Outcome, Status
from . import _kernels as kn
from . import _pack as pk
from ._legacy import SIMULATE_ALIASES
from .parameters import STATE_FIELDS, BipedParams, BipedState

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "BipedOptions",
    "BipedEvent",
    "Trajectory",
    "StepResult",
    "to_status",
    "MIN_CONTACT_FRACTION",
    "count_strides",
    "default_min_contact",
    "simulate",
    "step",
    "RECORD_COLUMNS",
]

#: Columns of :attr:`Trajectory.data`.
RECORD_COLUMNS: tuple[str, ...] = (
    ("t",) + STATE_FIELDS + ("contact_R", "contact_L", "Fx_R", "Fz_R", "Fx_L", "Fz_L",
                              "tau_R", "tau_L", "F_tR", "F_tL", "F_sR", "F_sL")
)


def state_unit(name: str) -> str:
    """Unit of a state field (eq. E.9) or its rate (``*_d``), Table 3.1."""
    base = name.removesuffix("_d")
    unit = "rad" if base.startswith("theta") else "L"
    if name.endswith("_d"):
        return "rad g^1/2 L^-1/2" if unit == "rad" else "g^1/2 L^1/2"
    return unit


#: Units of the biped's result tables: the recorded columns, the state and the contact state.
BIPED_UNITS: dict[str, str] = {
    "t": "g^-1/2 L^1/2", **{n: state_unit(n) for n in STATE_FIELDS},
    **dict.fromkeys(("contact_R", "contact_L", "on_R", "on_L", "status", "accepted",
                     "rho_R", "converged", "residual", "evaluations", "message"), "-"),
    **dict.fromkeys(("Fx_R", "Fz_R", "Fx_L", "Fz_L", "F_tR", "F_tL", "F_sR", "F_sL"), "Mg"),
    **dict.fromkeys(("tau_R", "tau_L"), "MgL"),
    **dict.fromkeys(("x_R", "z_R", "x_L", "z_L"), "L"),
}
#: The contact state ``(on_R, on_L, x_R, z_R, x_L, z_L)``: flags and touch-down anchors.
CONTACT_FIELDS = ("on_R", "on_L", "x_R", "z_R", "x_L", "z_L")


def to_status(code: int) -> Status:
    """The shared :class:`tslip.Status` of a biped kernel's code (``_pack.STATUS_NAMES``).

    The one place where the biped kernels' codes meet the shared enum: its
    falls (1-9), errors (10-19) and the end time (``T_END``, 20+).
    """
    return Status[pk.STATUS_NAMES[int(code)]]


def _m(description: str, lower: float, lower_open: bool = True, unit: str = "") -> dict:
    return {"description": description, "lower": lower, "lower_open": lower_open,
            "upper_open": True, "unit": unit}


_TIME = "g^-1/2 L^1/2"


@dataclass(frozen=True, slots=True, kw_only=True)
class BipedOptions:
    """Integrator options of the biped simulator.

    Parameters
    ----------
    rtol, atol : float
        Tolerances (thesis: 1e-8 with Dormand-Prince 5(4), Section E.2.5).
    h0, h_max, h_min : float
        First, largest and smallest step [g^-1/2 L^1/2] (``h0 = 0``: 1e-3).
    max_steps : int
        Step limit per run (accepted + rejected).
    stride_time_max : float
        A right touch-down must follow the previous one within this time
        [g^-1/2 L^1/2], otherwise the run is a fall.
    check_falls : bool
        Stop at falls (off for the free-flight conservation tests).
    max_records : int
        Rows of the recorded trajectory (one per accepted step and event).
    method : str
        Runge-Kutta pair of :mod:`tslip.simulation._rk`: ``"dopri5"``
        (Dormand-Prince 5(4), the thesis's) or ``"dop853"`` (8th order, fewer
        steps at tight tolerances).
    """

    rtol: float = field(default=1e-8, metadata=_m("relative tolerance", 0.0))
    atol: float = field(default=1e-8, metadata=_m("absolute tolerance", 0.0))
    h0: float = field(default=0.0, metadata=_m("first step (0: automatic)", 0.0, False, _TIME))
    h_max: float = field(default=0.05, metadata=_m("largest step", 0.0, True, _TIME))
    h_min: float = field(default=1e-12, metadata=_m("smallest step", 0.0, True, _TIME))
    max_steps: int = field(default=5_000_000, metadata=_m("step limit", 1.0, False))
    stride_time_max: float = field(default=5.0, metadata=_m("longest stride", 0.0, True, _TIME))
    check_falls: bool = True
    max_records: int = field(default=400_000, metadata=_m("recorded rows", 1.0, False))
    method: str = field(default="dopri5", metadata={"description": "Runge-Kutta pair",
                                                     "choices": METHODS})

    def __post_init__(self) -> None:
        check_fields(self, prefix="BipedOptions.")
        if self.method not in METHODS:
            raise ValueError(f"BipedOptions.method must be one of {', '.join(METHODS)}, "
                             f"got {self.method!r}")

    def pack(self, t_end: float = math.inf) -> NDArray[np.float64]:
        """Options vector for the kernels."""
        O = np.zeros(pk.NO)
        O[pk.O_RTOL] = self.rtol
        O[pk.O_ATOL] = self.atol
        O[pk.O_H0] = self.h0
        O[pk.O_HMAX] = self.h_max
        O[pk.O_HMIN] = self.h_min
        O[pk.O_MAXSTEPS] = self.max_steps
        O[pk.O_TSTRIDE] = self.stride_time_max
        O[pk.O_TEND] = t_end
        O[pk.O_FALLS] = 1.0 if self.check_falls else 0.0
        O[pk.O_METHOD] = METHODS.index(self.method)
        return O


#: Default minimum right-foot contact as a fraction of the nominal stance ``d T``.
MIN_CONTACT_FRACTION = 0.1


def default_min_contact(params: BipedParams) -> float:
    """Shortest contact that counts as a stance: ``MIN_CONTACT_FRACTION d T`` [g^-1/2 L^1/2]."""
    return MIN_CONTACT_FRACTION * params.d * params.T


_EVENT_NAMES = {pk.EV_TD_R: "touchdown_R", pk.EV_TD_L: "touchdown_L", pk.EV_LO_R: "liftoff_R",
                pk.EV_LO_L: "liftoff_L", pk.EV_FALL: "fall"}


@dataclass(frozen=True, slots=True)
class BipedEvent:
    """A contact event: time, kind and foot position (touch-down anchor)."""

    t: float
    kind: str
    foot_x: float
    foot_z: float


@dataclass(frozen=True, repr=False)
class Trajectory(Result):
    """A biped run, recorded at every accepted integrator step and event.

    The biped's counterpart of :class:`tslip.Trajectory` (both are
    :class:`tslip.protocols.RunLike`).

    Attributes
    ----------
    data : ndarray, shape (n, 31)
        Columns :data:`RECORD_COLUMNS`.
    events : list of BipedEvent
    strides : ndarray, shape (n_steps, 25)
        Time, state (18) and contact state (6) just after each right touch-down.
    status : Status
    params : BipedParams
    final_state : ndarray, shape (18,)
    final_contact : ndarray, shape (6,)
    stats : dict
        Accepted and rejected steps, right-hand-side calls.
    """

    data: NDArray[np.float64]
    events: list[BipedEvent]
    strides: NDArray[np.float64]
    status: Status
    params: BipedParams
    final_state: NDArray[np.float64]
    final_contact: NDArray[np.float64]
    stats: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> NDArray[np.float64]:
        return self.data[:, RECORD_COLUMNS.index(name)]

    def _repr_fields(self) -> dict[str, Any]:
        t = self.data[:, 0]
        return {"n_steps": self.n_steps, "samples": len(t),
                "t_from": t[0] if len(t) else None, "t_to": t[-1] if len(t) else None,
                "status": self.status}

    def plot(self, ax: Axes | None = None) -> Figure:
        """The right foot's path relative to the hip against the reference (Figure E.3)."""
        from ..plotting.biped import plot_foot_path

        return plot_foot_path(self, ax=ax)

    def _table_fields(self) -> tuple[str, ...]:
        return ("data",)

    @classmethod
    def _from_table(cls, df: pd.DataFrame, fields: dict[str, Any]) -> dict[str, Any]:
        data = df[list(RECORD_COLUMNS)].to_numpy(dtype=np.float64)
        return {**fields, "data": np.ascontiguousarray(data)}

    @property
    def time(self) -> NDArray[np.float64]:
        """Sample times [g^-1/2 L^1/2]."""
        return self.data[:, 0]

    @property
    def fell(self) -> bool:
        """True if the run ended in a fall."""
        return self.status.fell

    @property
    def n_steps(self) -> int:
        """Completed strides (right touch-downs after the start)."""
        return int(self.strides.shape[0])

    @property
    def n_strides(self) -> int:
        """Deprecated name of :attr:`n_steps` (removed in tslip 0.4)."""
        warn_renamed("Trajectory.n_strides", "Trajectory.n_steps")
        return self.n_steps

    def count_strides(self, min_contact: float | None = None) -> int:
        """Full strides, right touch-down to right touch-down, scuffs not counted.

        See :func:`count_strides`; ``min_contact`` defaults to
        :func:`default_min_contact` of the run's parameters.
        """
        mc = default_min_contact(self.params) if min_contact is None else min_contact
        return count_strides(self.events, t_end=float(self.stats.get("t_end", self.time[-1])),
                             fell=self.fell, min_contact=mc)

    def to_dataframe(self) -> pd.DataFrame:
        """The recorded time series, one row per sample (units in attrs)."""
        import pandas as pd

        return with_units(pd.DataFrame(self.data, columns=list(RECORD_COLUMNS)), BIPED_UNITS)


def count_strides(events: list[BipedEvent], *, t_end: float, fell: bool,
                  min_contact: float) -> int:
    """Full strides in a run that starts at a right touch-down (Section E.2.5).

    A stride ends at a right touch-down whose contact lasts at least
    ``min_contact`` [g^-1/2 L^1/2] (until the next right lift-off); shorter
    right contacts (scuffs) and every left-foot event are ignored. A right
    contact still on at ``t_end`` counts if it has lasted ``min_contact``,
    or if the run did not fall (it stopped at the requested touch-down).

    Raises
    ------
    ValueError
        If ``min_contact`` is negative or not finite.
    """
    if not (math.isfinite(min_contact) and min_contact >= 0):
        raise ValueError(f"min_contact [g^-1/2 L^1/2] must be in [0, inf), got {min_contact!r}")
    n = 0
    t_down: float | None = None
    for e in events:
        if e.kind == "touchdown_R":
            t_down = e.t
        elif e.kind == "liftoff_R" and t_down is not None:
            if e.t - t_down >= min_contact:
                n += 1
            t_down = None
    if t_down is not None and (t_end - t_down >= min_contact or not fell):
        n += 1
    return int(n)


def _check(params: Any, state: Any) -> tuple[BipedParams, NDArray[np.float64]]:
    if not isinstance(params, BipedParams):
        raise ValueError(f"params must be BipedParams, got {type(params).__name__}")
    if isinstance(state, BipedState):
        return params, state.to_array()
    return params, BipedState.from_array(state).to_array()


@accepts_n_strides
def simulate(
    params: BipedParams,
    state: BipedState | NDArray[np.float64],
    n_steps: int,
    *,
    t0: float = 0.0,
    t_end: float = math.inf,
    contact: NDArray[np.float64] | None = None,
    options: BipedOptions | None = None,
) -> Trajectory:
    """Simulate up to ``n_steps`` strides of the biped from ``state`` at ``t0``.

    Parameters
    ----------
    params : BipedParams
    state : BipedState or array_like, shape (18,)
        ``(q, qd)`` at time ``t0`` (eq. E.9).
    n_steps : int
        Number of right touch-downs to run through (>= 1). The old keyword
        ``n_strides`` still works, with a ``DeprecationWarning``, until 0.4.
    t0 : float
        Start time; sets the controller phase (eq. E.25).
    t_end : float
        Stop at this time if reached first.
    contact : array_like, shape (6,), optional
        Contact flags and touch-down anchors ``(on_R, on_L, x_R, z_R, x_L,
        z_L)``. Default: a foot at or below the ground that pushes is in
        contact, anchored at the ground (see :func:`._kernels.init_contact`).
    options : BipedOptions, optional

    Returns
    -------
    Trajectory
        Ends early at a fall (status says which) or integrator failure.

    Raises
    ------
    ValueError
        For invalid parameters, state, stride count or times.

    References
    ----------
    Thesis Appendix E, eqs E.22-E.34, Section E.2.5.
    """
    params, y0 = _check(params, state)
    if not isinstance(n_steps, (int, np.integer)) or n_steps < 1:
        raise ValueError(f"n_steps must be an integer >= 1, got {n_steps!r}")
    if not math.isfinite(t0):
        raise ValueError(f"t0 [g^-1/2 L^1/2] must be finite, got {t0!r}")
    if not t_end > t0:
        raise ValueError(f"t_end [g^-1/2 L^1/2] must be after t0 = {t0}, got {t_end!r}")
    options = options or BipedOptions()
    P = pk.pack_params(params)
    cs = np.zeros(pk.NCS)
    if contact is None:
        kn.init_contact(P, y0, cs)
    else:
        cs[:] = np.asarray(contact, dtype=np.float64)
    rec = np.empty((options.max_records, pk.NREC))
    ev = np.empty((8 * int(n_steps) + 16, pk.NEV))
    strides = np.empty((int(n_steps), pk.NSTRIDE))
    yend = np.empty(18)
    csend = np.empty(pk.NCS)
    stats = np.zeros(pk.NSTATS)
    st = kn.run(P, options.pack(t_end), float(t0), y0, cs, int(n_steps), rec, ev, strides,
                yend, csend, stats)
    n_ev = int(stats[pk.S_NEV])
    events = [
        BipedEvent(float(e[0]), _EVENT_NAMES[int(e[1])], float(e[2]), float(e[3]))
        for e in ev[:n_ev]
    ]
    return Trajectory(
        data=rec[: int(stats[pk.S_NREC])].copy(),
        events=events,
        strides=strides[: min(int(stats[pk.S_NSTRIDE]), int(n_steps))].copy(),
        status=to_status(st),
        params=params,
        final_state=yend,
        final_contact=csend,
        stats={"accepted": int(stats[pk.S_NACC]), "rejected": int(stats[pk.S_NREJ]),
               "rhs_calls": int(stats[pk.S_NFEV]), "t_end": float(stats[pk.S_TEND]),
               "records_full": bool(stats[pk.S_RECFULL])},
    )


@dataclass(frozen=True, slots=True, repr=False)
class StepResult(Result, Outcome):
    """One stride of the biped (right touch-down to the next), as :func:`step` returns it.

    The biped's counterpart of :class:`tslip.StepResult` (both are
    :class:`tslip.protocols.StepLike`).

    Attributes
    ----------
    status : Status
    t : float
        Time of the next right touch-down [g^-1/2 L^1/2].
    state : ndarray, shape (18,)
        State just after it (NaN if the stride failed).
    contact : ndarray, shape (6,)
    accepted : int
        Integrator steps taken.
    """

    status: Status
    t: float
    state: NDArray[np.float64]
    contact: NDArray[np.float64]
    accepted: int

    def _repr_fields(self) -> dict[str, Any]:
        return {"status": self.status, "t": self.t, "accepted": self.accepted}

    def to_dataframe(self) -> pd.DataFrame:
        """One row: the outcome, the next right touch-down's time, state and contact state."""
        row: dict[str, Any] = {"status": self.status.name, "t": self.t,
                               "accepted": self.accepted}
        row.update(zip(STATE_FIELDS, np.asarray(self.state).tolist()))
        row.update(zip(CONTACT_FIELDS, np.asarray(self.contact).tolist()))
        return frame([row], BIPED_UNITS)



_NO_REC = np.empty((0, pk.NREC))


def step(
    params: BipedParams,
    state: NDArray[np.float64],
    t0: float,
    *,
    contact: NDArray[np.float64] | None = None,
    options: BipedOptions | None = None,
    _P: NDArray[np.float64] | None = None,
) -> StepResult:
    """One stride from ``(t0, state)`` without recording (the step map's stride)."""
    options = options or BipedOptions()
    P = pk.pack_params(params) if _P is None else _P
    y0 = np.asarray(state, dtype=np.float64)
    cs = np.zeros(pk.NCS)
    if contact is None:
        kn.init_contact(P, y0, cs)
    else:
        cs[:] = contact
    ev = np.empty((16, pk.NEV))
    strides = np.empty((1, pk.NSTRIDE))
    yend = np.empty(18)
    csend = np.empty(pk.NCS)
    stats = np.zeros(pk.NSTATS)
    st = to_status(kn.run(P, options.pack(), float(t0), y0, cs, 1, _NO_REC, ev, strides, yend,
                          csend, stats))
    if st != Status.OK:
        return StepResult(st, float(stats[pk.S_TEND]), np.full(18, np.nan), csend,
                          int(stats[pk.S_NACC]))
    return StepResult(st, float(strides[0, 0]), strides[0, 1:19].copy(),
                      strides[0, 19:25].copy(), int(stats[pk.S_NACC]))


#: Old names (deprecated, removed in 0.4): docs/model.md, "Vocabulary".
__getattr__ = module_getattr(__name__, SIMULATE_ALIASES)
