"""
A 3-D TSLIP run: front and side views
=====================================

The Table 2.1 TSLIP in three dimensions (``tslip.spatial``, issue 43) runs from its
left-right symmetric gait (``tslip.spatial.lateral.TABLE21_3D_SECTION``, splay 0.05 rad)
with a small lateral push at the first touch-down. ``trunk_run`` records every stride
(``TrunkRun``: time, CoM, velocity, quaternion, yaw/pitch/roll, hip, foot and energy in
one table with units), and ``tslip.plotting.spatial.draw_views`` draws the runner from
the front (seen from ahead: the runner's right on the viewer's left) and from the side.
The lateral mode of this gait is unstable (docs/analyses/spatial_tslip.md), so the push
grows stride by stride until a leg lands across the body's mid-plane: the roll and the
lateral drift show it. ``tslip spatial animate -o run.gif --push 0.05`` writes the same
two views as an animation.
"""

# %%
import numpy as np

from tslip.plotting.spatial import draw_views
from tslip.spatial.lateral import TABLE21_3D_SECTION, table21_params
from tslip.spatial.trunk_run import trunk_run
from tslip.spatial.trunk_section import from_section

p = table21_params()
x = TABLE21_3D_SECTION.copy()
x[6] += 0.05  # a lateral push [g^1/2 L^1/2] added to vz at the first touch-down
run = trunk_run(p, from_section(p, x), 20)
print(run)
df = run.to_dataframe()
print(df[["t", "stride", "stance", "z", "roll", "energy"]].iloc[::40].to_string(index=False))
print("units:", {c: df.attrs["units"][c] for c in ("t", "z", "roll", "energy")})

# %%
# The runner in the middle of its last stance, from the front and from the side.
last = run.data[(run["stride"] == run.n_strides - 1) & (run["stance"] > 0.5)]
views = draw_views(run, float(np.mean(last[:, 0])))  # views.savefig("views.png") writes it

# %%
# The CoM path with the footholds, from the side and from above: the lateral drift grows.
paths = run.plot()
