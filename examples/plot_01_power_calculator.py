"""
Power calculator: equivalent linearisation
==========================================

The expected electrical power of the paper's Section 5 device under white base
acceleration, by equivalent linearisation (paper Eq. 19-32), swept over the
Coulomb friction level ``Fc`` and the noise level ``S`` in one broadcast call,
and the load resistance that maximises the power delivered to the load; then
which analytic methods accept a case, as they declare it.
"""

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

device = rv.preset("figure9")  # c_m = c_e = 0.1 Ns/m, Fc = 0.0058 N
print(f"c_eq  = {rv.equivalent_damping(device, psd=1.0):.5f} Ns/m  (Eq. 30)")
print(f"E[P_e] = {1e3 * rv.expected_power(device, psd=1.0):.4f} mW  (Eq. 32)")

# %%
# A sweep is one call: the friction level and the PSD broadcast against each
# other (here a 3 x 51 table of powers).
fc = np.linspace(0.0, 0.05, 51)
psd = np.array([[1.0], [0.5], [0.1]])
power = rv.expected_power(device.updated(fc=fc), psd=psd)

fig, ax = plt.subplots(layout="constrained")
for s, row in zip(psd[:, 0], power, strict=True):
    ax.plot(1e3 * fc, 1e3 * row, label=f"S = {s:g} (m/s$^2$)$^2$/Hz")
ax.set_xlabel("Coulomb friction $F_c$ (mN)")
ax.set_ylabel("expected electrical power (mW)")
ax.legend()

# %%
# The circuit (Eq. 3): a coil of flux gradient ``alpha`` and resistance
# ``R_C`` feeding a load ``R_L``. The optimal load balances the electrical and
# the mechanical damping.
wired = rv.Harvester.from_electrical(
    m=0.0226,
    c_m=0.049,
    k=57.4,
    k3=70742,
    alpha=0.1992,
    r_load=2.0,
    r_coil=0.48,
    friction=rv.Coulomb(0.0058),
)
r_opt, p_opt = rv.optimal_load_resistance(wired, 1.0)
print(f"R_L* = {r_opt:.3f} ohm, P_L* = {1e3 * p_opt:.4f} mW")

# %%
# Four analytic methods predict the power (``rv.METHODS``). Each declares what
# it accepts, so a script asks them rather than keeping its own list: under a
# band-pass excitation only statistical linearisation applies, and a method
# that does not refuses with one line naming the ones that do.
band = rv.BandPass(level=1.0, f0=8.0, zeta=0.2)
for name, method in rv.METHODS.items():
    print(f"{name:14} white: {method.accepts(device, 1.0)}, band-pass: "
          f"{method.accepts(device, band)}  ({method.summary})")  # fmt: skip
print(rv.METHODS["fpk-fast"].refusal(device, band))

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
