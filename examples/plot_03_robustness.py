"""
Robustness to a step-down
=========================

How large a step down can the Table 6.1 runner take without falling (thesis Section
3.1.3)? ``robustness_report`` finds the step-down, push and pitch-rate limits; the figure
follows the touch-down states stride by stride after a step of half the limit.
"""

# %%

import tslip
from tslip.gait import step_down_response
from tslip.plotting import plot_step_down_response

gait = tslip.find_gait(tslip.preset("table6.1"))
report = tslip.robustness_report(gait)
for lim in report.limits:
    print(f"{lim.kind:>10}: {lim.limit:+.4f} {lim.unit}  ({lim.reason})")

dh = 0.5 * report.get("step_down").limit          # half the step-down limit (< 0)
resp = step_down_response(gait, dh=dh, n_steps=15)
fig = plot_step_down_response(resp)   # fig.savefig("step_down.png") writes it
