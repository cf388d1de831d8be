"""
A SLIP's self-stable region
===========================

The classic spring-loaded inverted pendulum (SLIP) is the TSLIP's limit with the mass at
the hip (``r = 0``), no hip torque, no damping and a leg reset to a fixed angle in the
inertial frame: the ``slip`` preset. Its periodic gaits at fixed speed are self-stable
only in a band of leg angles. At ``r = 0`` the pitch decouples, and ``floquet`` sets its
two multipliers aside (with the energy's) as trivial, so the largest non-trivial
multiplier and the label describe the SLIP itself.
"""

# %%
import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import tslip

slip = tslip.preset("slip")            # r = 0, Passive(), c_l = 0, global leg reset
fl = tslip.floquet(tslip.find_gait(slip))
print(f"slip preset: largest non-trivial |lambda| {fl.max_nontrivial:.4f} ({fl.stability}); "
      f"trivial: {[k for k in fl.trivial_kinds if k]}")

betas = np.linspace(1.17, 1.35, 8)
ks = np.linspace(15.0, 35.0, 5)
lam = np.full((ks.size, betas.size), np.nan)
for i, k in enumerate(ks):
    for j, b in enumerate(betas):
        g = tslip.find_gait(dataclasses.replace(slip, k=float(k), beta0=float(b),
                                                alpha_r=float(b)))
        if g.converged:
            lam[i, j] = tslip.floquet(g).max_nontrivial
print(f"{np.sum(lam < 1)} of {lam.size} (k, beta0) pairs self-stable, "
      f"{np.sum(np.isnan(lam))} without a gait")

fig, ax = plt.subplots(figsize=(5, 4))
mesh = ax.pcolormesh(betas, ks, lam, shading="nearest", cmap="RdYlGn_r", vmin=0.0, vmax=2.0)
fig.colorbar(mesh, label="largest non-trivial |lambda| [-]")
ax.contour(betas, ks, lam, levels=[1.0], colors="k")
ax.set(xlabel="beta0 [rad]", ylabel="k [Mg/L]", title=f"SLIP (r = 0), v0 = {slip.v0:g}")
plt.show()
