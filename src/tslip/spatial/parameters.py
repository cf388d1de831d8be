"""Parameters of the 3-D spring-mass runner (3D-SLIP; Seipel & Holmes 2005; issue 43).

Dimensionless in the units of the planar model (thesis Table 3.1: body mass M,
gravity g, rest leg length L); ``m``, ``l0`` and ``g`` are kept as parameters
so that a missing factor shows when they differ from 1. Frame: x forward, y up,
z = x cross y (the runner's right). Legs alternate; side ``s = +1`` is the
right leg, ``-1`` the left.

Touch-down happens when the mass descends to the height ``l0 sin(beta0)``;
the foot is placed at

    p = c + l0 [cos(beta0) (cos(gamma) h + s sin(gamma) n) - sin(beta0) e_y],

``h`` the heading (a horizontal unit vector), ``n = h x e_y`` (to the right of
``h``), ``gamma = gamma0 + k_lat s v_n`` with ``v_n`` the velocity along ``n``
at touch-down (gamma > 0 puts the foot outward, on the stance leg's side).

``heading="fixed"``: ``h = +x`` (the runner's mean direction, an inertial
reference). ``heading="velocity"``: ``h`` is the direction of the horizontal
velocity at touch-down (the model is then invariant under yaw); ``v_n = 0``
by construction, so ``k_lat`` has no effect under that rule and a ``k_lat != 0``
is refused.

Planar limit: with ``gamma0 = 0`` and no lateral motion the model is the
planar SLIP (``tslip.preset("slip")``) whose leg angle ``alpha_r`` (= its
``beta0``; docs/conventions.md: measured from +x down to the leg) equals
``beta0`` here, with the same ``k``, ``m``, ``l0``, ``g``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, Literal, get_args, overload

import numpy as np

from .._checks import check_fields
from ..model.parameters import preset as _planar_preset
from ._kernels import NP, P_G, P_K, P_L0, P_M
from .trunk_parameters import TrunkParams

__all__ = ["SpatialParams", "HEADINGS", "Heading", "TABLE21_3D_SPLAY", "preset",
           "preset_description", "presets"]

Heading = Literal["fixed", "velocity"]
#: The allowed values of :attr:`SpatialParams.heading`.
HEADINGS: tuple[str, ...] = get_args(Heading)


def _f(default: float, unit: str, description: str, lower: float = -math.inf,
       upper: float = math.inf, lower_open: bool = True, upper_open: bool = True) -> object:
    return field(default=default, metadata={
        "unit": unit, "description": description, "lower": lower, "upper": upper,
        "lower_open": lower_open, "upper_open": upper_open})


@dataclass(frozen=True, slots=True, kw_only=True)
class SpatialParams:
    """The 3-D spring-mass runner (module docstring).

    Defaults: the planar ``slip`` preset's spring and angle (k 25, beta0 1.19)
    with unit mass, leg and gravity, the leg placed straight ahead
    (``gamma0 = 0``), no feedback, fixed heading.
    """

    m: float = _f(1.0, "M", "body mass", 0.0)  # type: ignore[assignment]
    k: float = _f(25.0, "MgL^-1", "leg spring stiffness", 0.0)  # type: ignore[assignment]
    l0: float = _f(1.0, "L", "rest leg length", 0.0)  # type: ignore[assignment]
    g: float = _f(1.0, "g", "gravitational acceleration", 0.0)  # type: ignore[assignment]
    beta0: float = _f(1.19, "rad", "angle of attack from the ground plane", 0.0,  # type: ignore[assignment]
                      math.pi / 2)
    gamma0: float = _f(0.0, "rad", "leg azimuth about the vertical (+: outward)",  # type: ignore[assignment]
                       -math.pi / 2, math.pi / 2)
    k_lat: float = _f(0.0, "rad g^-1/2 L^-1/2",  # type: ignore[assignment]
                      "lateral feedback gain: gamma = gamma0 + k_lat s v_n")
    heading: Heading = field(default="fixed", metadata={
        "description": "heading reference h of the leg placement", "choices": HEADINGS})

    def __post_init__(self) -> None:
        check_fields(self, prefix="SpatialParams.")
        if not (isinstance(self.heading, str) and self.heading in HEADINGS):
            raise ValueError(f"SpatialParams.heading must be 'fixed' or 'velocity', "
                             f"got {self.heading!r}")
        if self.heading == "velocity" and self.k_lat != 0.0:
            raise ValueError(
                f"SpatialParams.k_lat must be 0 with heading='velocity' (v_n is 0 by "
                f"construction there, so the feedback has no effect), got {self.k_lat!r}")

    def to_dict(self) -> dict[str, Any]:
        """Plain ``dict`` of the fields (JSON friendly; the run record of a saved result)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def packed(self) -> np.ndarray:
        """The kernel's parameter vector (:mod:`tslip.spatial._kernels`)."""
        P = np.zeros(NP)
        P[P_M], P[P_K], P[P_L0], P[P_G] = self.m, self.k, self.l0, self.g
        return P

    @property
    def touchdown_height(self) -> float:
        """Height of the mass at touch-down, ``l0 sin(beta0)`` [L]."""
        return self.l0 * math.sin(self.beta0)


_PRESETS: dict[str, tuple[str, dict[str, object]]] = {
    "slip3d": ("3-D spring-mass runner: the planar slip preset's k 25 and beta0 1.19, leg "
               "azimuth gamma0 0.05 outward, no feedback, fixed heading",
               dict(k=25.0, beta0=1.19, gamma0=0.05)),
    "slip3d-feedback": ("slip3d with the lateral feedback k_lat 1.5 (stabilises its fast "
                        "symmetric gait at energy 2.2: docs/analyses/spatial.md)",
                        dict(k=25.0, beta0=1.19, gamma0=0.05, k_lat=1.5)),
}


#: The default splay [rad] of the 3-D Table 2.1 TSLIP: small, so that the foot lands
#: outside the body's mid-plane (at splay 0 any roll crosses a leg) and the gait stays
#: close to the planar one (docs/analyses/spatial_tslip.md).
TABLE21_3D_SPLAY = 0.05

#: The TSLIP presets (:class:`~tslip.spatial.trunk_parameters.TrunkParams`): description.
_TRUNK_PRESETS: dict[str, str] = {
    "table2.1-3d": (f"the TSLIP of thesis Table 2.1 in 3-D: the planar table2.1 preset with "
                    f"J_roll = J_yaw = J and splay {TABLE21_3D_SPLAY} rad, no roll coupling"),
}


def presets() -> list[str]:
    """Names accepted by :func:`preset`."""
    return [*_PRESETS, *_TRUNK_PRESETS]


def preset_description(name: str) -> str:
    """One-line description of a preset."""
    key = _key(name)
    return _PRESETS[key][0] if key in _PRESETS else _TRUNK_PRESETS[key]


def _key(name: Any) -> str:
    key = name.strip().lower() if isinstance(name, str) else name
    if key not in _PRESETS and key not in _TRUNK_PRESETS:
        raise ValueError(f"preset must be one of {presets()}, got {name!r}")
    return str(key)


@overload
def preset(name: Literal["table2.1-3d"]) -> TrunkParams: ...  # type: ignore[overload-overlap]
@overload
def preset(name: str) -> SpatialParams: ...


def preset(name: str) -> SpatialParams | TrunkParams:
    """Named 3-D parameter set: the 3-D spring-mass runner (``slip3d``,
    ``slip3d-feedback``: :class:`SpatialParams`) and the 3-D TSLIP of Table 2.1
    (``table2.1-3d``: :class:`~tslip.spatial.trunk_parameters.TrunkParams`, the planar
    ``tslip.preset("table2.1")`` with ``J_roll = J_yaw = J`` and ``splay``
    :data:`TABLE21_3D_SPLAY`).

    Raises
    ------
    ValueError
        If ``name`` is not one of :func:`presets`.
    """
    key = _key(name)
    if key in _TRUNK_PRESETS:
        return TrunkParams.from_planar(_planar_preset("table2.1"), splay=TABLE21_3D_SPLAY)
    return SpatialParams(**_PRESETS[key][1])  # type: ignore[arg-type]
