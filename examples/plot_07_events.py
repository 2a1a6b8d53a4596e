"""
Events: the energy of one passing vehicle, and the end stop
===========================================================

Much real vibration comes in events. An event is a stationary excitation
times a deterministic envelope ``e(t)`` that starts at t = 0
(:class:`randvib.Enveloped`): here band-pass noise at the device's resonance
under a Shinozuka-Sato envelope ``A (exp(-b t) - exp(-c t))`` scaled to a
peak of 1. Monte Carlo (:func:`randvib.simulate_transient`) follows the
ensemble from rest; the Lyapunov differential equation
(:func:`randvib.transient_response`) gives the same moments analytically,
exactly for the linear device and by time-dependent statistical
linearisation for the nonlinear one.
"""

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

device = rv.preset("figure9").updated(stroke=0.005)  # the paper's device, a 5 mm stroke
event = rv.Enveloped(rv.BandPass(2.0, 8.0, 0.2), rv.ShinozukaSato.unit_peak(0.5, 2.0))
times = np.linspace(0.0, 6.0, 31)

simulated = rv.simulate_transient(
    device, event, t_end=6.0, dt=2.5e-4, n_paths=400, times=times, seed=1, progress=False
)
linearised = rv.transient_response(device, event, np.linspace(0.0, 6.0, 301))
energy = simulated.energy_electrical
print(f"energy per event, Monte Carlo:    {1e3 * energy.mean:.3f} +- {1e3 * energy.ci95:.3f} mJ")
print(f"energy per event, linearisation:  {1e3 * linearised.energy_electrical:.3f} mJ")
reached = simulated.peak_exceedance(0.005)
print(f"P(|z| reaches 5 mm in the event): {reached} (95 % Wilson interval)")

# %%
# Through the event: the mean-square displacement and the power (Monte Carlo
# with its 95 % band beside the analytic curve), the energy harvested since
# the event began (the whole event's Monte Carlo energy as one marker at its
# end), P(``|z|`` has reached the stroke) with its Wilson interval, and the
# envelope's intensity e(t)^2 (dotted). ``randvib simulate --envelope ...
# --plot FILE.png`` draws the same figure.
rv.plot_transient({"paper's device": (simulated, linearised)})

# %%
# The same event on the linear device (no friction, no spring), where the
# Lyapunov solution is exact and the probability of reaching the stroke has
# the standard out-crossing approximations (Poisson: independent crossings;
# Vanmarcke: crossings in clumps), labelled approximate.
linear = device.updated(fc=0.0, k3=0.0)
exact = rv.transient_response(linear, event, times)
mc = rv.simulate_transient(
    linear, event, t_end=6.0, dt=2.5e-4, n_paths=400, times=times, seed=1, progress=False
)
print(exact)
print(f"Monte Carlo P(stroke reached by 6 s): {mc.stroke_reached.mean[-1]:.3f}")

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
