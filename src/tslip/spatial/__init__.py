"""Running in three dimensions (issue 43).

Part 1, the 3-D spring-mass runner (3D-SLIP) of Seipel & Holmes (2005):

* :mod:`.parameters`: :class:`SpatialParams` (spring, leg angles, feedback, heading rule)
  and the presets of both parts (:func:`preset`);
* :mod:`.stride`: the apex-to-apex step, its statuses and its exact Jacobian;
* :mod:`.gait`: left-right symmetric gaits and the Floquet multipliers of the two-step map;
* :mod:`._kernels`: the compiled stance loop on the project's Runge-Kutta core.

Part 2, the TSLIP in three dimensions (docs/analyses/spatial_tslip.md):

* :mod:`.trunk_parameters`: :class:`TrunkParams` (Table 2.1 with ``J_roll``, ``J_yaw``,
  ``splay`` and the roll couplings ``k_splay``, ``k_trail``);
* :mod:`.trunk`: the stride touch-down -> touch-down (:func:`trunk_step`), its statuses
  (:class:`TrunkStatus`, the crossed leg among the falls) and the planar-limit maps;
* :mod:`.trunk_section`: the 10-D touch-down section (:data:`TRUNK_SECTION_NAMES`), its
  mirror, left-right symmetric gaits (:func:`symmetric_gait`) and the two-step map and
  its Jacobian (exact by default, or by central differences);
* :mod:`.trunk_jacobian`: the exact one- and two-step Jacobians (variational equations
  with the event-time corrections; the compiled part in :mod:`._trunk_variational`);
* :mod:`.trunk_run`: a recorded multi-stride run (:func:`trunk_run`, :class:`TrunkRun`),
  drawn in a front and a side view by :mod:`tslip.plotting.spatial`;
* :mod:`._trunk_kernels`: the compiled stance and flight loop on the same core;
  :mod:`._trunk_stride`: the whole stride as one compiled kernel on it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # the names as the type checker sees them
    from .gait import Multipliers, SymmetricGait, floquet, symmetric_gaits
    from .parameters import HEADINGS, SpatialParams, preset, preset_description, presets
    from .stride import (
        SECTION_NAMES,
        SpatialApex,
        SpatialStatus,
        SpatialStep,
        apex_step,
        apex_steps,
        energy,
        mirror,
        section_map,
        step_jacobian,
    )
    from .trunk import TrunkStatus, TrunkStep, TrunkTouchdown, trunk_energy, trunk_step
    from .trunk_parameters import TrunkParams
    from .trunk_run import TrunkRun, trunk_run
    from .trunk_section import MIRROR as TRUNK_MIRROR
    from .trunk_section import SECTION_NAMES as TRUNK_SECTION_NAMES
    from .trunk_section import (
        from_section,
        mirror_section,
        one_step_map,
        section,
        symmetric_gait,
        two_step_jacobian,
        two_step_map,
        yaw_rotated,
    )

#: Each public name: (its module, its name there); loaded on first use (PEP 562), so that
#: importing a submodule (the 3-D parameters, for a study's spec) does not load them all
_LAZY = {
    'Multipliers': ('gait', 'Multipliers'),
    'SymmetricGait': ('gait', 'SymmetricGait'),
    'floquet': ('gait', 'floquet'),
    'symmetric_gaits': ('gait', 'symmetric_gaits'),
    'HEADINGS': ('parameters', 'HEADINGS'),
    'SpatialParams': ('parameters', 'SpatialParams'),
    'preset': ('parameters', 'preset'),
    'preset_description': ('parameters', 'preset_description'),
    'presets': ('parameters', 'presets'),
    'SECTION_NAMES': ('stride', 'SECTION_NAMES'),
    'SpatialApex': ('stride', 'SpatialApex'),
    'SpatialStatus': ('stride', 'SpatialStatus'),
    'SpatialStep': ('stride', 'SpatialStep'),
    'apex_step': ('stride', 'apex_step'),
    'apex_steps': ('stride', 'apex_steps'),
    'energy': ('stride', 'energy'),
    'mirror': ('stride', 'mirror'),
    'section_map': ('stride', 'section_map'),
    'step_jacobian': ('stride', 'step_jacobian'),
    'TrunkStatus': ('trunk', 'TrunkStatus'),
    'TrunkStep': ('trunk', 'TrunkStep'),
    'TrunkTouchdown': ('trunk', 'TrunkTouchdown'),
    'trunk_energy': ('trunk', 'trunk_energy'),
    'trunk_step': ('trunk', 'trunk_step'),
    'TrunkParams': ('trunk_parameters', 'TrunkParams'),
    'TrunkRun': ('trunk_run', 'TrunkRun'),
    'trunk_run': ('trunk_run', 'trunk_run'),
    'TRUNK_MIRROR': ('trunk_section', 'MIRROR'),
    'TRUNK_SECTION_NAMES': ('trunk_section', 'SECTION_NAMES'),
    'from_section': ('trunk_section', 'from_section'),
    'mirror_section': ('trunk_section', 'mirror_section'),
    'one_step_map': ('trunk_section', 'one_step_map'),
    'section': ('trunk_section', 'section'),
    'symmetric_gait': ('trunk_section', 'symmetric_gait'),
    'two_step_jacobian': ('trunk_section', 'two_step_jacobian'),
    'two_step_map': ('trunk_section', 'two_step_map'),
    'yaw_rotated': ('trunk_section', 'yaw_rotated'),
}

__all__ = ["HEADINGS", "SpatialParams", "preset", "preset_description", "presets",
           "SECTION_NAMES", "SpatialApex", "SpatialStatus", "SpatialStep", "apex_step",
           "apex_steps", "energy", "mirror", "section_map", "step_jacobian", "Multipliers",
           "SymmetricGait", "floquet", "symmetric_gaits",
           # Part 2: the 3-D TSLIP
           "TrunkParams", "TrunkStatus", "TrunkStep", "TrunkTouchdown", "trunk_energy",
           "trunk_step", "TRUNK_MIRROR", "TRUNK_SECTION_NAMES", "from_section",
           "mirror_section", "one_step_map", "section", "symmetric_gait", "two_step_jacobian",
           "two_step_map", "yaw_rotated", "TrunkRun", "trunk_run"]


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
