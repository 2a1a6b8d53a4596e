"""
A measured record: its spectrum, the predicted power and Monte Carlo on it
==========================================================================

A harvester is usually judged on vibration someone measured: an
accelerometer's file of time and base acceleration. randvib reads it as a
:class:`randvib.Measured` excitation, whose one-sided PSD (Welch's method,
Hann window, 50 % overlap) feeds statistical linearisation, and simulates the
device on the record itself (:func:`randvib.monte_carlo_on_record`): the
record is cut into windows that each start from the state the record drove
the device into, and the windows' means give a t-interval.

The file here is written by the example itself (a 4-20 Hz band-limited
acceleration of RMS 1.07 m/s^2, as on the paper's shaker) so that the example
runs anywhere; with a real file only the ``from_csv`` line is needed.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import randvib as rv

folder = Path(tempfile.mkdtemp())
shaker = rv.synthetic_record(
    rv.preset("figure9"), 1.07, duration=60.0, sample_rate=500.0, seed=3, input="base_acceleration"
)
accelerometer = rv.Record(shaker.dt, base_acceleration=shaker.input)  # the input channel only
accelerometer.to_csv(folder / "accelerometer.csv")

# %%
# Reading the record: columns ``time`` and ``base_acceleration`` (m/s^2).
measured = rv.Measured.from_csv(folder / "accelerometer.csv")
print(measured)
f = np.linspace(0.5, 40.0, 400)
fig, ax = plt.subplots(layout="constrained")
ax.semilogy(f, measured.psd(f))
ax.set_xlabel("frequency (Hz)")
ax.set_ylabel("base acceleration PSD ((m/s$^2$)$^2$/Hz, one-sided)")

# %%
# The expected electrical power of the paper's device on this spectrum
# (statistical linearisation), and Monte Carlo on the record itself, with its
# interval over 12 windows (valid while a window is much longer than the
# response's correlation time: ``lag1_correlation`` near zero).
device = rv.preset("figure9")
predicted = rv.expected_power(device, measured)
simulated = rv.monte_carlo_on_record(device, measured, segments=12, burn_in=1.0, progress=False)
power = simulated.power_electrical
print(f"linearisation on the Welch PSD: {1e3 * predicted:.4f} mW")
print(f"Monte Carlo on the record:      {1e3 * power.mean:.4f} +- {1e3 * power.ci95:.4f} mW (95 %)")
print(f"lag-1 correlation of the windows' means: {simulated.lag1_correlation:.2f}")

plt.show()  # run as a script: the figures in windows (the gallery draws them itself)
