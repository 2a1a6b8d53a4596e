"""
A piezoelectric harvester
=========================

A device with a piezoelectric coupling (force ``theta V`` on the mass,
``C_p dV/dt + V / R_L = theta v`` in the circuit) instead of the coil: the
voltage is a state of the linearised system and of the simulation. The power
into the load and the load that maximises it, predicted and simulated.
"""

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

piezo = rv.Piezo(theta=1e-3, capacitance=1e-7, r_load=1e5)  # N/V, F, ohm
device = rv.Harvester.with_coupling(0.0226, 0.05, 57.4, piezo, friction=rv.Coulomb(0.002))
prediction = rv.predict(device, 0.5)
print(f"linearisation: P_L = {1e6 * prediction.power_load:.3f} uW")
result = rv.simulate(device, 0.5, t_end=8.0, burn_in=2.0, dt=5e-4, n_paths=300, seed=2)
p = result.power_load
print(f"Monte Carlo:   P_L = {1e6 * p.mean:.3f} +- {1e6 * p.ci95:.3f} uW (95 %)")

# %%
# The load resistance: a search over R_L with the friction, and the power
# against R_L (one linearisation per value).
r_opt, p_opt = rv.optimal_load_resistance(device, 0.5)
print(f"optimal load: R_L* = {r_opt:.4g} ohm, P_L* = {1e6 * p_opt:.3f} uW")
loads = np.geomspace(1e3, 1e7, 41)
powers = [rv.expected_power(device.updated(r_load=r), 0.5, into="load") for r in loads]
fig, ax = plt.subplots(layout="constrained")
ax.semilogx(loads, 1e6 * np.asarray(powers))
ax.axvline(r_opt, ls=":", color="k", label="optimum")
ax.set_xlabel("load resistance $R_L$ ($\\Omega$)")
ax.set_ylabel("power into the load ($\\mu$W)")
ax.legend()

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
