"""
A SLIP's self-stable region
===========================

The classic spring-loaded inverted pendulum (SLIP) is the TSLIP's limit with the mass at
the hip (``r = 0``), no hip torque, no damping and a leg reset to a fixed angle in the
inertial frame: the ``slip`` preset. As the SLIP literature does, we hold the total
energy. At a given energy and leg angle the SLIP has two periodic gaits, a flat
self-stable one and a steep unstable one (``all_gaits`` finds both); ``stable_region``
solves every cell of a (k, beta0) grid on its own and marks where a stable gait exists.
At ``r = 0`` the pitch decouples, and ``floquet`` sets its two multipliers aside (with
the energy's) as trivial, so the largest non-trivial multiplier describes the SLIP.
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import tslip

slip = tslip.preset("slip")            # r = 0, Passive(), c_l = 0, global leg reset
energy = 2.2                            # total energy [MgL]
gaits = tslip.all_gaits(slip, energy=energy)
for g, f in zip(gaits, gaits.floquets):
    print(f"apex height {g.apex.y:.4f}, velocity angle at touch-down {g.state.delta:+.4f}: "
          f"largest non-trivial |lambda| {f.max_nontrivial:.4f} ({f.stability})")

region = tslip.stable_region(slip, {"k": np.linspace(15.0, 35.0, 5),
                                    "beta0": np.linspace(1.15, 1.35, 9)}, energy=energy)
print(region)
fig, ax = plt.subplots(figsize=(5.5, 4.2))
region.plot(ax=ax)                      # no gait / unstable only / a stable gait
plt.show()
