"""
A first gait
============

Solve the periodic gait of the thesis's passive model (Table 2.1), check its Floquet
multipliers, and record a run of ten strides.
"""

# %%

import tslip
from tslip.plotting import plot_trajectory

params = tslip.preset("table2.1")      # Table 2.1, dimensionless units (Table 3.1)
gait = tslip.find_gait(params)         # solves delta, phi, phid and alpha_r (Section 2.8)
print(f"stance {gait.stance_time:.4f}, flight {gait.flight_time:.4f}, "
      f"residual {gait.residual:.1e}")

# A conservative runner keeps its energy: one multiplier is exactly 1 (the energy's, set
# aside as trivial); the others lie inside the unit circle, so the gait is asymptotically
# stable on its energy level (docs/conventions.md).
fl = tslip.floquet(gait)               # exact multipliers (variational equations)
print(f"largest non-trivial |lambda| = {fl.max_nontrivial:.3f}: {fl.stability}")

traj = tslip.simulate(gait.params, gait.state, n_steps=10)
fig = plot_trajectory(traj)   # a matplotlib Figure; fig.savefig("run.png") writes it
