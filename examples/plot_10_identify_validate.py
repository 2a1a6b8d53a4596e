"""
From a record to a validated model: record, identify, validate
==============================================================

The paper's workflow (Sec. 3-4): record the device on a shaker, fit the
device model (Eq. 1) with a friction law to one record by minimising the
normalised cost J (Eq. 11; J < 1 is an excellent fit), then check the fitted
model on records it has not seen, at other excitation levels. Here the
"shaker" is :func:`randvib.synthetic_record` of the paper's Coulomb device,
with the laser's noise and offset, written to and read back from CSV files
as real records would be. The search is deliberately small (seconds); real
fits use the defaults.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import randvib as rv

folder = Path(tempfile.mkdtemp())
truth = rv.preset("coulomb-td1")
levels = {"test A": 0.8, "test B": 1.07, "test C": 1.4}  # RMS base acceleration (m/s^2)
for i, (name, rms) in enumerate(levels.items()):
    rv.synthetic_record(truth, rms, duration=4.0, sample_rate=500.0, seed=10 + i,
                        noise_z=1e-6, offset_z=1e-4, name=name).to_csv(folder / f"{name}.csv")  # fmt: skip

# %%
# Identify: a Coulomb model fitted to test B, with the magnet mass given (a
# base-excited record cannot separate it from the other parameters).
training = rv.read_record(folder / "test B.csv")
result = rv.identify(training, "coulomb", m=0.0226,
                     search=rv.SearchSettings(popsize=20, maxiter=30, seed=1))  # fmt: skip
print(result)

# %%
# Validate: the identified device, with its measurement model (offsets), on
# every record. J stays low on the records it was not fitted to.
device = result.harvester()
costs = {}
for name in levels:
    record = rv.read_record(folder / f"{name}.csv")
    costs[name] = rv.predict_record(device, record, measurement=result.measurement).cost
    print(f"{name} (RMS {levels[name]:g} m/s^2): J = {costs[name]:.3g}")

fig, ax = plt.subplots(layout="constrained")
ax.plot(list(levels.values()), list(costs.values()), "o")
ax.set_xlabel("RMS base acceleration (m/s$^2$)")
ax.set_ylabel("normalised cost J (Eq. 11)")
ax.set_ylim(bottom=0)
ax.set_title("fitted on test B (1.07 m/s$^2$)")

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
