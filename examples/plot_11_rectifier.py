"""
DC power through a diode bridge
===============================

The paper's power, E[P_e] = c_e E[z'^2] (Eq. 32), and the power into a
matched resistor are AC figures. A real harvester charges a battery, or a
storage capacitor with its load, through a full-wave bridge: no current flows
until the coil's EMF ``alpha z'`` exceeds the output voltage plus two diode
drops. ``rv.BridgeCoil`` is that coupling; ``rv.simulate`` reports where the
input power went (stored, lost in the coil, in the diodes, mechanically), and
``"bridge-closure"`` predicts the stored power of a battery, so that
``rv.optimal_dc_output`` can choose its voltage.

The device is the paper's (preset ``figure9``: Coulomb friction Fc = 5.8 mN)
with the paper's coil, alpha = 0.1992 Wb/m, R_C = 0.48 ohm, under white noise
S = 1 (m/s^2)^2/Hz; the diodes drop 10 mV each.
"""

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

base = rv.preset("figure9")
psd, alpha, r_coil, v_diode = 1.0, 0.1992, 0.48, 0.01


def wired(coupling):
    """The figure9 device's mechanics with ``coupling`` as its electrical side."""
    return rv.Harvester.with_coupling(base.m, base.c_m, base.k, coupling, k3=base.k3,
                                      friction=base.friction)  # fmt: skip


# small ensembles, fixed seeds: a few seconds (scale n_paths and t_end up for real work)
mc = dict(t_end=8.0, dt=2e-4, burn_in=2.0, n_paths=48, seed=3, control_variates=True,
          progress=False)  # fmt: skip

# %%
# The resistive figure: the coil into a matched load R_L = R_C.
resistive = wired(rv.Resistive(alpha, r_coil, r_coil))
print(f"resistive, R_L = R_C: E[P_L] = {1e3 * rv.predict(resistive, psd).power_load:.3f} mW "
      "(linearisation)")  # fmt: skip
p_resistive = rv.simulate(resistive, psd, **mc).power_load
print(f"resistive, R_L = R_C: E[P_L] = {1e3 * p_resistive.mean:.3f} "
      f"± {1e3 * p_resistive.ci95:.3f} mW (Monte Carlo)")  # fmt: skip

# %%
# A battery: the closure's best voltage, and where the input went in
# Monte Carlo at that voltage (the four parts add up to m S / 4 under white noise).
battery = wired(rv.BridgeCoil(alpha, r_coil, v_diode=v_diode, battery=0.03))
best = rv.optimal_dc_output(battery, psd)
print(best)  # the closure's optimal battery voltage, and whether it is interior
at_best = wired(rv.BridgeCoil(alpha, r_coil, v_diode=v_diode, battery=best.value))
run = rv.simulate(at_best, psd, **mc)
for name in ("power_stored", "power_coil_loss", "power_diode_loss", "power_mechanical"):
    s = getattr(run, name)
    print(f"  {name:17s} {1e3 * s.mean:.3f} ± {1e3 * s.ci95:.3f} mW")
print(f"  input m S / 4     {1e3 * base.m * psd / 4:.3f} mW")

# %%
# A storage capacitor (0.1 F) with its 2.5 ohm load (R_L C = 0.25 s, well
# inside the 2 s burn-in): the stored power is E[V_C^2] / R_L.
capacitor = wired(rv.BridgeCoil(alpha, r_coil, v_diode=v_diode, storage_capacitance=0.1,
                                r_load=2.5))  # fmt: skip
p_capacitor = rv.simulate(capacitor, psd, **mc).power_stored
print(f"capacitor + load: stored {1e3 * p_capacitor.mean:.3f} ± {1e3 * p_capacitor.ci95:.3f} mW")

# %%
# Stored power against the battery voltage: the closure's curve, Monte Carlo
# at three voltages (95 % intervals; the last beyond the closure's range),
# the capacitor + load and the resistive figure for scale. Even the best
# battery stores well under what a matched resistor takes: the bridge
# conducts only on the largest velocity peaks.
volts = np.linspace(0.002, best.upper, 25)  # best.upper: where the closure stops
closure = [rv.predict(wired(rv.BridgeCoil(alpha, r_coil, v_diode=v_diode, battery=v)), psd,
                      "bridge-closure").power_stored for v in volts]  # fmt: skip
checked = (0.01, best.value, 0.05)
measured = [rv.simulate(wired(rv.BridgeCoil(alpha, r_coil, v_diode=v_diode, battery=v)), psd,
                        **mc).power_stored for v in checked]  # fmt: skip

fig, ax = plt.subplots(layout="constrained")
ax.plot(1e3 * volts, 1e3 * np.asarray(closure), color="C0", label="battery, bridge closure")
ax.errorbar(1e3 * np.asarray(checked), [1e3 * s.mean for s in measured],
            yerr=[1e3 * s.ci95 for s in measured], fmt="o", color="C0", capsize=3,
            label="battery, Monte Carlo (95 %)")  # fmt: skip
ax.axhline(1e3 * p_resistive.mean, color="k", ls="--", label="resistive figure, $R_L = R_C$")
ax.axhline(
    1e3 * p_capacitor.mean, color="C1", ls=":", label="capacitor 0.1 F + 2.5 Ω load, Monte Carlo"
)
ax.set_xlabel("battery voltage $V_b$ (mV)")
ax.set_ylabel("power (mW)")
ax.set_ylim(bottom=0.0)
ax.set_title(f"bridge with $V_d$ = {1e3 * v_diode:g} mV, S = {psd:g} (m/s²)²/Hz")
_ = ax.legend(fontsize=8, loc="center right")

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
