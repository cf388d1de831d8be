"""
A SLIP's self-stable region
===========================

The classic spring-loaded inverted pendulum (SLIP) is the TSLIP's limit with the mass at
the hip (``r = 0``), no hip torque, no damping and a leg reset to a fixed angle in the
inertial frame. Its periodic gaits at fixed speed are self-stable only in a band of leg
angles; this scans the leg angle and stiffness and marks where the multiplier that is
not 1 by structure (energy, the decoupled pitch) is below one.
"""

# %%
import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import tslip

slip = dataclasses.replace(tslip.preset("table2.1"), r=0.0, c_l=0.0, omega_r=0.0,
                           leg_reset="global", v0=2.0)
betas = np.linspace(1.1, 1.35, 8)
ks = np.linspace(15.0, 35.0, 5)
lam = np.full((ks.size, betas.size), np.nan)
for i, k in enumerate(ks):
    for j, b in enumerate(betas):
        p = dataclasses.replace(slip, k=float(k), beta0=float(b), alpha_r=float(b))
        g = tslip.find_gait(p)
        if g.converged:
            # three multipliers are 1 by structure (energy; pitch angle and rate, which
            # decouple at r = 0) and one is 0 (the leg angle is reset): the other decides
            m = np.abs(tslip.floquet(g).multipliers)
            lam[i, j] = m[~np.isclose(m, 1.0, atol=1e-4)].max()

print(f"{np.sum(lam < 1 - 1e-6)} of {lam.size} (k, beta0) pairs self-stable, "
      f"{np.sum(np.isnan(lam))} without a gait")
fig, ax = plt.subplots(figsize=(5, 4))
mesh = ax.pcolormesh(betas, ks, lam, shading="nearest", cmap="RdYlGn_r", vmin=0.5, vmax=1.5)
fig.colorbar(mesh, label="largest non-trivial |lambda| [-]")
ax.contour(betas, ks, lam, levels=[1.0], colors="k")
ax.set(xlabel="beta0 [rad]", ylabel="k [Mg/L]", title="SLIP (r = 0), v0 = 2")
plt.show()
