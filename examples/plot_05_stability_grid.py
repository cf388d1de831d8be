"""
A 2-D stability grid
====================

Where in the plane of leg stiffness ``k`` and touch-down angle ``beta0`` is the passive
runner (neutrally) stable? A coarse version of the thesis's Figure 4.10 at ``v0 = 5``.
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import tslip
from tslip.sweeps import Axis, StudySpec, run_study

base = tslip.preset("table2.1")
spec = StudySpec("k-beta0", base, axes=(Axis("k", tuple(np.linspace(15, 35, 6))),
                                        Axis("beta0", tuple(np.linspace(0.95, 1.15, 6)))),
                 analyses=("floquet",))

if __name__ == "__main__":          # a study with workers starts processes: guard the entry
    res = run_study(spec, workers=1)
    grid = res.grid("max_nontrivial")            # shape (len(k axis), len(beta0 axis))
    k, beta0 = (np.asarray(a.values) for a in spec.axes)
    fig, ax = plt.subplots(figsize=(5, 4))
    mesh = ax.pcolormesh(beta0, k, grid, shading="nearest", cmap="RdYlGn_r",
                         vmin=0.8, vmax=1.2)
    fig.colorbar(mesh, label="largest non-trivial |lambda| [-]")
    ax.set(xlabel="beta0 [rad]", ylabel="k [Mg/L]", title="Passive model, v0 = 5")
    print(f"{np.mean(grid <= 1 + 1e-6):.0%} of the grid is at least neutral")
    plt.show()
