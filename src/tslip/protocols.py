"""What the TSLIP's and the biped's results share, as protocols (docs/model.md, "Vocabulary").

The two models have one vocabulary: the same names for one stride, a run, a
status, a periodic gait, its Floquet multipliers and its robustness. Where
their results differ (a touch-down state against an 18-entry section vector,
:class:`~tslip.Params` against :class:`~tslip.biped.BipedParams`), code
written for both can rely on these members, and type checkers check it.
Each protocol is ``runtime_checkable``: ``isinstance`` checks that the
members exist (not their types).

================  ===============================  =====================================
protocol          TSLIP                            biped
================  ===============================  =====================================
StepLike          ``tslip.StepResult``             ``tslip.biped.StepResult``
RunLike           ``tslip.Trajectory``             ``tslip.biped.Trajectory``
GaitLike          ``tslip.Gait``                   ``tslip.biped.gait.Gait``
FloquetLike       ``tslip.Floquet``                ``tslip.biped.gait.Floquet`` (a subclass)
LimitLike         ``tslip.gait.RobustnessLimit``   the same class
RobustnessLike    ``tslip.gait.RobustnessResult``  ``tslip.biped.robustness.RobustnessResult``
================  ===============================  =====================================
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from .simulation.result import Status

__all__ = ["StepLike", "RunLike", "GaitLike", "FloquetLike", "LimitLike", "RobustnessLike"]


@runtime_checkable
class StepLike(Protocol):
    """One stride, touch-down to the next touch-down (the biped: of the right foot)."""

    @property
    def status(self) -> Status: ...

    @property
    def state(self) -> Any:
        """The state at the next touch-down (``None`` or NaN after a fall)."""
        ...

    @property
    def fell(self) -> bool: ...

    @property
    def ok(self) -> bool: ...

    @property
    def reason(self) -> str: ...


@runtime_checkable
class RunLike(Protocol):
    """A run of several strides, sampled in time."""

    @property
    def status(self) -> Status: ...

    @property
    def params(self) -> Any: ...

    @property
    def time(self) -> np.ndarray: ...

    @property
    def fell(self) -> bool: ...

    def __getitem__(self, name: str) -> np.ndarray:
        """One recorded column by name."""
        ...

    def to_dataframe(self) -> Any: ...


@runtime_checkable
class GaitLike(Protocol):
    """A periodic gait: a fixed point of the step map, or the best candidate found."""

    @property
    def params(self) -> Any: ...

    @property
    def residual(self) -> float: ...

    @property
    def converged(self) -> bool: ...

    @property
    def message(self) -> str: ...


@runtime_checkable
class FloquetLike(Protocol):
    """Floquet multipliers of a gait and the stability they give (eq. 2.21)."""

    @property
    def multipliers(self) -> np.ndarray: ...

    @property
    def magnitudes(self) -> np.ndarray: ...

    @property
    def max_nontrivial(self) -> float: ...

    @property
    def stability(self) -> str: ...

    @property
    def stable(self) -> bool: ...

    @property
    def jacobian(self) -> np.ndarray: ...


@runtime_checkable
class LimitLike(Protocol):
    """The robustness limit of one disturbance and direction (Section 3.1.3)."""

    @property
    def kind(self) -> str: ...

    @property
    def sign(self) -> int: ...

    @property
    def limit(self) -> float: ...

    @property
    def first_failing(self) -> float: ...

    @property
    def status(self) -> Status: ...

    @property
    def reason(self) -> str: ...

    @property
    def unit(self) -> str: ...


@runtime_checkable
class RobustnessLike(Protocol):
    """Robustness limits of a gait: one :class:`LimitLike` per disturbance and direction."""

    @property
    def limits(self) -> Sequence[LimitLike]: ...

    def get(self, kind: str, sign: int = -1) -> LimitLike: ...

    @property
    def step_down(self) -> float: ...

    @property
    def push(self) -> float: ...

    @property
    def pitch_rate(self) -> float: ...

    @property
    def n_steps(self) -> int: ...

    @property
    def tol(self) -> float: ...


if TYPE_CHECKING:  # mypy checks that both models' classes conform (never run)
    from . import biped as _biped
    from .biped import gait as _bg
    from .biped import robustness as _br
    from .gait import fixed_point as _fp
    from .gait import stability as _st
    from .gait.robustness import RobustnessLimit as _Limit
    from .gait.robustness import RobustnessResult as _Robust
    from .simulation import result as _res

    def _conforms(s: _res.StepResult, bs: _biped.StepResult, r: _res.Trajectory,
                  br: _biped.Trajectory, g: _fp.Gait, bg: _bg.Gait, f: _st.Floquet,
                  bf: _bg.Floquet, lim: _Limit, rr: _Robust,
                  brr: _br.RobustnessResult) -> None:
        steps: list[StepLike] = [s, bs]
        runs: list[RunLike] = [r, br]
        gaits: list[GaitLike] = [g, bg]
        floquets: list[FloquetLike] = [f, bf]
        limits: list[LimitLike] = [lim]
        robust: list[RobustnessLike] = [rr, brr]
        del steps, runs, gaits, floquets, limits, robust
