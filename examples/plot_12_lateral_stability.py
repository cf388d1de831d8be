"""
Lateral stability of the TSLIP in 3-D
=====================================

The Table 2.1 gait carried into three dimensions (``tslip.spatial``, issue 43 Part 2):
the legs splay outward by a small angle, the trunk can roll and yaw, and the left-right
symmetric gait is found by continuation from the planar one
(``tslip.spatial.lateral.table21_gait``). Its two-step map has three trivial
multipliers (energy, heading and the heading's Jordan partner); the largest of the other
seven decides the lateral stability. Without a coupling it is a real multiplier well
above 1 that grows with the mass offset ``r``: the lateral mode (roll, lateral velocity,
roll rate) is unstable. Coupling the leg placement to the trunk's roll, by more splay
(``k_splay``) or a yaw of the placement (``k_trail``, the bicycle-like trail of thesis
Section 7.8), brings it close to 1 but not below (docs/analyses/spatial_tslip.md).
"""

# %%
import matplotlib.pyplot as plt

from tslip.spatial.lateral import gain_table, r_table

by_r = r_table((0.1, 0.3, 0.5))
for p in by_r:
    print(f"r {p.params.r:.1f}: largest non-trivial |multiplier| {p.largest:.4f} ({p.kind})")
by_splay_gain = gain_table((0.0, 1.0, 2.0), (0.0,))
by_trail = gain_table((0.0,), (0.0, 1.0, 2.0, 4.0))

fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6), sharey=True)
a.plot([p.params.r for p in by_r], [p.largest for p in by_r], "o-")
a.set(xlabel="mass offset r [L]", ylabel="largest non-trivial |multiplier|",
      title="no coupling, splay 0.05")
b.plot([p.params.k_splay for p in by_splay_gain], [p.largest for p in by_splay_gain], "o-",
       label="k_splay (k_trail 0)")
b.plot([p.params.k_trail for p in by_trail], [p.largest for p in by_trail], "s-",
       label="k_trail (k_splay 0)")
b.set(xlabel="coupling gain", title="r 0.3, splay 0.05")
for ax in (a, b):
    ax.axhline(1.0, color="k", lw=0.8, ls="--")
b.legend()
plt.tight_layout()
plt.show()
