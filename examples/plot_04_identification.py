"""
Identification on a synthetic record
====================================

A synthetic shaker record of a device with Coulomb friction (the paper's
band-limited 4-20 Hz base acceleration, displacement sensor noise), then the
device model (Eq. 1) with Coulomb friction fitted to it by minimising the
normalised cost J (Eq. 11) with self-adaptive differential evolution. The
search here is deliberately small (a few seconds); real fits use the defaults.
"""

import matplotlib.pyplot as plt

import randvib as rv

truth = rv.preset("coulomb-td1")
record = rv.synthetic_record(
    truth, 1.07, duration=4.0, sample_rate=500.0, seed=1, noise_z=1e-6
)  # RMS 1.07 m/s^2
result = rv.identify(
    record,
    "coulomb",
    m=truth.m,
    search=rv.SearchSettings(popsize=20, maxiter=40, seed=1),
)
print(f"cost J = {result.cost:.3g} (J < 1 is an excellent fit)")
true_values = {"c": truth.c, "k": truth.k, "k3": truth.k3, "fc": truth.friction.fc}
for name, value in true_values.items():
    print(f"{name:3s} true {value:10.4g}   identified {result.parameters[name]:10.4g}")

# %%
# The identified device is a Harvester (its damping c as c_m), with a
# measurement model (the sensors' offsets); simulated on the record it was
# fitted to, it scores the fit's J.
device = result.harvester()
print(device)
print(result.measurement)
fitted = rv.predict_record(device, record, measurement=result.measurement)
print(f"J on the record: {fitted.cost:.3g}, RMS error {1e6 * fitted.rms_error:.2f} um")
t = record.time
fig, ax = plt.subplots(layout="constrained")
ax.plot(t, 1e3 * record.z, lw=1, label="record")
ax.plot(t, 1e3 * fitted.z, lw=1, ls="--", label="identified model")
ax.set_xlabel("time (s)")
ax.set_ylabel("relative displacement $z$ (mm)")
ax.set_xlim(0, 1)
ax.legend()

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
