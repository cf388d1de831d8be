"""
Beyond the thesis: a power-law leg, leg thrust and a retraction stop
====================================================================

The thesis closes (Sections 7.5 and 7.8) with what it could not try: a non-linear leg
stiffness, leg-length variation and stopping the swing leg's retraction at an angle.
All three are parameters of ``tslip.Params`` (``leg_exponent``, ``leg_thrust``,
``alpha_stop``; docs "The model"). This script measures what each does to the largest
non-trivial Floquet multiplier and to the three robustness limits (25 strides, the
thesis's -1 direction) of the Table 2.1 (passive) and Table 6.1 (local velocity control)
gaits, and prints the numbers the docs page "Beyond the thesis" quotes.

* ``n`` (``leg_exponent``) at fixed ``k`` changes the stiffness and the shape at once, so
  it is also run holding the spring force at the ``n = 1`` gait's largest compression
  ``x*``: ``k_n = k x*^(1 - n)``.
* ``d`` (``leg_thrust``) adds energy each stance; the passive Table 2.1 model has no leg
  damping to spend it, so it has no periodic gait for ``d > 0``. With leg damping
  ``c_l > 0`` and the passive hip the gait search solves ``d`` (powered running at the
  set speed): that line is a study over ``c_l``, plotted against the ``d`` it needs.
* ``alpha_stop`` binds only after a disturbance (a stop that binds at the gait is
  refused), so the gait and its multipliers stay as they are; it is run at offsets
  beyond the gait's touch-down angle, for both leg resets.
"""

# %%
import dataclasses
import math
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import tslip
from tslip.gait import robustness_report
from tslip.sweeps import StudySpec, run_study

KINDS = ("step_down", "push", "pitch_rate")
COLUMNS = ("max_nontrivial", *KINDS)


def analyse(p: tslip.Params) -> dict[str, float]:
    """The largest multiplier and the three limits of the periodic gait of ``p``."""
    out = dict.fromkeys(COLUMNS, math.nan)
    g = tslip.find_gait(p)
    if not g.converged:
        return out
    fl = tslip.floquet(g, method="fd" if p.leg_exponent < 1 else "exact")
    out["max_nontrivial"] = fl.max_nontrivial
    if fl.max_nontrivial < 1:
        report = robustness_report(g)
        out.update({lim.kind: lim.limit for lim in report.limits})
    return out


def study(name: str, preset: str, param: str, values: list[float],
          keep: str | None = None) -> dict[str, np.ndarray]:
    """A study spec over one parameter (continued point to point), run serially; ``keep``
    names the column to key the result by (default the swept parameter)."""
    spec = StudySpec.from_dict({
        "name": name, "preset": preset, "analyses": ["floquet", "robustness"],
        "axis": [{"param": param, "values": values}]})
    frame = run_study(spec, Path(tempfile.mkdtemp()) / name, workers=1).frame
    return {c: frame[c].to_numpy() for c in (keep or param, *COLUMNS)}


exponents = [0.6, 0.8, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0]
thrusts = [0.0, 0.01, 0.02, 0.04, 0.06, 0.08, 0.1]
offsets = [0.02, 0.05, 0.08, 0.12, 0.16, 0.2, 0.3]
results: dict[str, dict[str, dict[str, np.ndarray]]] = {"n": {}, "d": {}, "stop": {}}

for preset in ("table2.1", "table6.1"):
    base = tslip.preset(preset)
    # n at fixed k: a study spec
    results["n"][f"{preset}, fixed k"] = study(f"n-{preset}", preset, "leg_exponent",
                                              exponents)
    # n with the force held at x*: k_n = k x*^(1 - n)
    g1 = tslip.find_gait(base)
    x_star = (base.l0 - tslip.step(g1.params, g1.state).stance[:, 1].min()) / base.l0
    rows = [analyse(dataclasses.replace(base, leg_exponent=n, k=base.k * x_star ** (1 - n)))
            for n in exponents]
    results["n"][f"{preset}, force held at x* = {x_star:.3f}"] = {
        "leg_exponent": np.array(exponents),
        **{c: np.array([r[c] for r in rows]) for c in COLUMNS}}
    # the retraction stop, both resets
    for reset in ("local", "global"):
        p = dataclasses.replace(base, leg_reset=reset)
        g = tslip.find_gait(p)
        alpha_td = g.state.beta + (g.state.phi if reset == "local" else 0.0)
        free = analyse(p)
        rows = [analyse(dataclasses.replace(p, alpha_stop=alpha_td + o)) for o in offsets]
        results["stop"][f"{preset}, {reset} reset"] = {
            "offset": np.array([0.0, *offsets]), "alpha_td": np.array(alpha_td),
            **{c: np.array([free[c]] + [r[c] for r in rows]) for c in COLUMNS}}

# leg thrust: Table 6.1 (leg damping c_l = 0.32 spends what the thrust adds)
results["d"]["table6.1"] = study("d-table6.1", "table6.1", "leg_thrust", thrusts)
passive_thrust = tslip.find_gait(dataclasses.replace(tslip.preset("table2.1"),
                                                     leg_thrust=0.02))
print(f"Table 2.1 with leg_thrust 0.02: periodic gait found: {passive_thrust.converged}")
# Table 2.1 with leg damping: the search solves the thrust that makes up for it
results["d"]["table2.1, c_l 0.02-0.3 (d solved)"] = study(
    "cl-table2.1", "table2.1", "c_l", [0.02, 0.05, 0.1, 0.2, 0.3], keep="leg_thrust")

# %%
# The numbers
# -----------
# Each row: the largest non-trivial multiplier and the step-down [L], push
# [g^1/2 L^1/2] and pitch-rate [rad g^1/2 L^-1/2] limits (NaN: no gait, or unstable).

for what, label in (("n", "leg_exponent"), ("d", "leg_thrust"), ("stop", "offset")):
    for name, r in results[what].items():
        print(f"\n{what}: {name}")
        print(f"{label:>13} {'max |lambda|':>13} {'step_down':>10} {'push':>10} "
              f"{'pitch_rate':>10}")
        for i, x in enumerate(r[label]):
            print(f"{x:13.3f} {r['max_nontrivial'][i]:13.4f} {r['step_down'][i]:10.4f} "
                  f"{r['push'][i]:10.4f} {r['pitch_rate'][i]:10.4f}")

# %%
# The figure
# ----------
# Columns: the leg exponent, the leg thrust, the stop's offset beyond the gait's
# touch-down angle (0: no stop). Rows: the largest multiplier and the three limits.

fig, axes = plt.subplots(4, 3, figsize=(11, 10), sharex="col", layout="constrained")
xlabels = {"n": "leg exponent n [-]", "d": "leg thrust d [-]",
           "stop": r"$\alpha_{stop} - \alpha_{TD}$ [rad] (0: no stop)"}
ylabels = ("largest |multiplier| [-]", "step-down limit [L]",
           r"push limit [$g^{1/2} L^{1/2}$]", r"pitch-rate limit [rad $g^{1/2} L^{-1/2}$]")
for j, (what, label) in enumerate((("n", "leg_exponent"), ("d", "leg_thrust"),
                                   ("stop", "offset"))):
    for name, r in results[what].items():
        for i, c in enumerate(COLUMNS):
            axes[i, j].plot(r[label], r[c], "o-", ms=3, label=name)
    axes[-1, j].set_xlabel(xlabels[what])
    axes[0, j].legend(fontsize=7)
for i, ylabel in enumerate(ylabels):
    axes[i, 0].set_ylabel(ylabel)
