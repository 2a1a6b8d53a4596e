"""
A bistable device with a stroke limit
=====================================

A negative linear stiffness with a hardening cubic spring, k < 0 < k3, gives
a double well: wells at z = +-sqrt(-k/k3), a barrier k^2/(4 k3) between them.
Such a device is often proposed for broadband harvesting, but it also swings
further, and a real magnet has an end stop. ``stroke=`` (m) changes nothing
in the dynamics; every method that can reports how much of the time ``|z|``
exceeds it (``stroke_exceedance``), and Monte Carlo also how soon it is first
reached from rest.

Linearisation puts one Gaussian over the barrier and gets the double well's
displacement wrong; the Fokker-Planck solvers (``fpk-fast``, ``fpk``) solve
for the stationary density itself.
"""

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

device = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=-25.3, k3=5e5, stroke=0.0085)
potential = device.potential
print(f"{potential.kind}: wells at ±{1e3 * potential.wells[-1]:.2f} mm, "
      f"barrier {1e6 * potential.barrier_height:.0f} µJ, stroke 8.5 mm")  # fmt: skip

# %%
# The potential energy and the stroke: the wells lie inside it, a swing over
# the barrier carries the magnet towards it.
z = np.linspace(-0.012, 0.012, 401)
fig, ax = plt.subplots(layout="constrained")
ax.plot(1e3 * z, 1e6 * potential.energy(z), color="k")
for side in (-1, 1):
    ax.axvline(side * 8.5, color="0.5", ls=":", lw=1)
ax.set_xlabel("relative displacement $z$ (mm)")
ax.set_ylabel("potential energy (µJ)")
ax.set_title("dotted: the stroke limit, |z| = 8.5 mm")

# %%
# Power and stroke exceedance at S = 0.5 (m/s^2)^2/Hz by three analytic
# methods and by Monte Carlo (from rest, with a 2 s burn-in).
psd = 0.5
for method in ("linearisation", "fpk-fast", "fpk"):
    p = rv.predict(device, psd, method)
    print(f"{method:14s} E[P_e] {1e3 * p.power_electrical:.4f} mW, "
          f"P(|z| > stroke) {p.stroke_exceedance:.4f}")  # fmt: skip
mc = rv.simulate(device, psd, t_end=12.0, dt=5e-4, burn_in=2.0, n_paths=256, initial="rest",
                 seed=1, progress=False)  # fmt: skip
print(f"Monte Carlo    E[P_e] {1e3 * mc.power_electrical.mean:.4f} "
      f"± {1e3 * mc.power_electrical.ci95:.4f} mW, P(|z| > stroke) "
      f"{mc.stroke_exceedance:.4f} (95 % Wilson interval)")  # fmt: skip

# %%
# How soon from rest: the mean first time ``|z|`` reaches the stroke, reported
# only when every path reached it within the run (otherwise a restricted
# mean, a lower bound).
passage = mc.stroke_first_passage
print(f"{passage.paths_reached} of {passage.n_paths} paths reached the stroke within "
      f"{passage.horizon:g} s; mean first passage {1e3 * passage.mean.mean:.0f} "
      f"± {1e3 * passage.mean.ci95:.0f} ms")  # fmt: skip

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
