"""
Ground impulse and the metacentre
=================================

Why does a runner with its mass hanging below the hip right itself after a pitch
disturbance? Thesis Chapter 3: the ground reaction impulse of the next stance passes
above the centre of mass and turns the trunk back. The figure shows the impulse of the
first stance after pitch disturbances of either sign (thesis Figures 4.2-4.3).
"""

# %%

import tslip
from tslip.gait import pitch_disturbance_response
from tslip.plotting import plot_pitch_impulse

gait = tslip.find_gait(tslip.preset("table2.1"))
resp = pitch_disturbance_response(gait, dphis=(0.0, 0.5, -0.5))
for imp, dphi in zip(resp.impulses, (0.0, 0.5, -0.5), strict=True):
    print(f"dphi {dphi:+.1f}: impulse ({imp.I_x:.3f}, {imp.I_y:.3f}) at "
          f"({imp.x_p:+.4f}, {imp.y_p:+.4f}) from the CoM")
fig = plot_pitch_impulse(resp)   # fig.savefig("impulse.png") writes it
