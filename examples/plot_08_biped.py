"""
The two-legged model
====================

Thesis Appendix E: a trunk with two massed legs and a parametric gait controller. From
the thesis's Table E.2 start the runner falls after a few strides; the stored gait
refined from that start (``converged-e2``) is periodic and stable.
"""

# %%
import matplotlib.pyplot as plt

from tslip.biped import BipedParams, BipedState, simulate
from tslip.biped.gait import floquet, to_section
from tslip.biped.stored import load_gait
from tslip.plotting.biped import plot_foot_path

run = simulate(BipedParams(), BipedState.thesis(), n_steps=20)
print(f"from Table E.2: {run.n_steps} strides, then {run.status.reason}")

p, y, t0, _ = load_gait("converged-e2")
stable = simulate(p, BipedState.from_array(y), n_steps=6, t0=t0)
print(f"converged-e2: {stable.n_steps} strides, largest multiplier "
      f"{floquet(p, to_section(p, y, t0)).max_nontrivial:.3f}")

fig, ax = plt.subplots(figsize=(7, 3))
plot_foot_path(stable, leg=0, ax=ax)
ax.set_title("Right foot path of the stored periodic gait")
plt.show()
