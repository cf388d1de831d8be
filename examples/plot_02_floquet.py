"""
Floquet multipliers
===================

The multipliers of the Table 6.1 gait (the fit to the Planar Elliptical Runner), computed
exactly from the variational equations and by the thesis's central differences
(eq. B.2), drawn against the unit circle.
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import tslip

gait = tslip.find_gait(tslip.preset("table6.1"))
exact = tslip.floquet(gait)                    # default: exact
fd = tslip.floquet(gait, method="fd")          # eq. B.2
print("exact:", np.round(exact.multipliers, 4))
print("fd:   ", np.round(fd.multipliers, 4))
print(f"largest |lambda| = {exact.max_nontrivial:.4f} ({exact.stability}); "
      "the thesis reports 0.92")

fig, ax = plt.subplots(figsize=(4.5, 4.5))
t = np.linspace(0, 2 * np.pi, 400)
ax.plot(np.cos(t), np.sin(t), "k-", lw=0.8)
ax.plot(exact.multipliers.real, exact.multipliers.imag, "o", mfc="none", ms=10, label="exact")
ax.plot(fd.multipliers.real, fd.multipliers.imag, "x", label="central differences")
ax.set(xlabel="Re lambda [-]", ylabel="Im lambda [-]", aspect="equal",
       title="Floquet multipliers, Table 6.1 gait")
ax.legend(loc="lower left")
plt.show()
