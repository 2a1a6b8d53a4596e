"""
A sweep over the friction level
===============================

``randvib.montecarlo.sweep.run_sweep`` runs a list of parameter points to a
target relative precision: it adds paths until the 95 % half-width of the
power is below the target, with common random numbers across points and the
energy-balance control variates. Here a small sweep over the Coulomb level
``Fc`` is compared with equivalent linearisation (Eq. 32) and the fast
Fokker-Planck solver.
"""

from concurrent.futures import ThreadPoolExecutor

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv
from randvib.montecarlo.sweep import SweepSettings, cartesian, run_sweep

device = rv.preset("figure9")
points = cartesian(psd=[1.0], fc=[0.0, 0.01, 0.02, 0.03])
settings = SweepSettings(dt=2.5e-4, window=2.0, burn_in=0.5, target_rel_ci=0.01, seed=0)
with ThreadPoolExecutor(max_workers=1) as executor:
    result = run_sweep(device, points, settings, executor=executor, progress=False)
table = result.table
print(
    table[
        ["fc", "power_electrical", "power_electrical_ci95", "linearisation_power", "n_paths"]
    ].to_string(index=False)
)

# %%
# The analytic methods over the same range, in one broadcast call each.
fc = np.linspace(0.0, 0.03, 61)
fig, ax = plt.subplots(layout="constrained")
for method in ("linearisation", "fpk-fast"):
    ax.plot(1e3 * fc, 1e3 * rv.expected_power(device.updated(fc=fc), 1.0, method), label=method)
ax.errorbar(
    1e3 * table["fc"],
    1e3 * table["power_electrical"],
    yerr=1e3 * table["power_electrical_ci95"],
    fmt="o",
    capsize=4,
    label="Monte Carlo, 95 % interval",
)
ax.set_xlabel("Coulomb friction $F_c$ (mN)")
ax.set_ylabel("expected electrical power (mW)")
ax.legend()

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
