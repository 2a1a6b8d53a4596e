"""Design on a measured record (:mod:`randvib.harvester_design.design`).

A record is searched with its Welch spectrum and confirmed on the record
itself (:func:`randvib.monte_carlo_on_record`, its windows the paths, the
same windows for every candidate). The confirmed power and exceedance are
checked against an independent run of the returned device on the record.
"""

import numpy as np
import pytest
from scipy import signal

import randvib as rv
from randvib.analytic.harvesting_limit import record_harvesting_limit
from randvib.montecarlo.sweep import SweepSettings

M, C_M = 0.0226, 0.049
FS = 100.0  #: record sample rate (Hz)


@pytest.fixture(scope="module")
def record() -> rv.Measured:
    """100 s of band-pass (5-11 Hz) Gaussian base acceleration, 3 m/s^2 RMS, fixed seed."""
    rng = np.random.default_rng(1)
    n = int(100 * FS)
    b, a = signal.butter(2, [5.0, 11.0], btype="bandpass", fs=FS)
    acc = signal.lfilter(b, a, rng.standard_normal(n))
    acc *= 3.0 / acc.std()
    return rv.Measured(rv.Record(time=np.arange(n) / FS, base_acceleration=acc), segment_length=128)


@pytest.fixture(scope="module")
def hardening_design(record):
    fixed = rv.Harvester(m=M, c_m=C_M, c_e=0.1, k=57.4, k3=2e5, stroke=0.004)
    settings = SweepSettings(dt=1e-3, burn_in=2.0, seed=0, control_variates=False)
    return rv.design(fixed, record, {"c_e": (0.01, 1.0)}, exceedance=0.01, settings=settings,
                     segments=10)  # fmt: skip


def test_a_record_is_confirmed_on_its_own_windows(record, hardening_design):
    r = hardening_design
    assert r.monte_carlo_input == "record windows"
    assert r.to_dict()["monte_carlo_input"] == "record windows"
    # an independent run of the returned device on the same record: other windows
    # (8 instead of 10), another burn-in, step and seed
    again = rv.monte_carlo_on_record(r.device, record, segments=8, burn_in=3.0, substeps=4,
                                     seed=7, progress=False)  # fmt: skip
    for confirmed, independent in (
        (r.power_monte_carlo, again.power_electrical),
        (r.stroke_exceedance_monte_carlo, again.stroke_exceedance),
    ):
        # two estimates of one record's time average: within their combined 95 % half-widths
        assert abs(confirmed.mean - independent.mean) <= np.hypot(confirmed.ci95, independent.ci95)
    # the confirmation used the record's windows: a Gaussian-path run would have n_paths >= 32
    assert r.power_monte_carlo.n_paths == 10


@pytest.fixture(scope="module")
def short_record() -> rv.Measured:
    """20 s of band-pass (5-11 Hz) Gaussian base acceleration at 100 Hz, 3 m/s^2 RMS."""
    fs = 100.0
    rng = np.random.default_rng(2)
    n = int(20 * fs)
    b, a = signal.butter(2, [5.0, 11.0], btype="bandpass", fs=fs)
    acc = signal.lfilter(b, a, rng.standard_normal(n))
    acc *= 3.0 / acc.std()
    return rv.Measured(rv.Record(time=np.arange(n) / fs, base_acceleration=acc), segment_length=128)


def test_record_limit_without_an_active_stroke_is_m2_a2_over_4cm(short_record):
    a = short_record.acceleration - np.mean(short_record.acceleration)
    # E[a^2] of the line between samples (what the simulation is driven by)
    mean_square = np.mean((a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3)
    exact = M**2 * mean_square / (4 * C_M)  # z' = -m a / (2 c_m) everywhere
    assert record_harvesting_limit(M, C_M, short_record, 10.0) == pytest.approx(exact, rel=1e-12)


def test_record_limit_decreases_as_the_stroke_shrinks(short_record):
    strokes = [0.008, 0.003, 0.001]
    limits = [record_harvesting_limit(M, C_M, short_record, z) for z in strokes]
    unconstrained = record_harvesting_limit(M, C_M, short_record, 10.0)
    assert limits[0] <= unconstrained
    assert all(x > y for x, y in zip(limits, limits[1:], strict=False))
    assert limits[-1] > 0


def test_record_limit_bounds_every_device_on_the_same_record(short_record):
    # devices of the design study's families, each held within |z| <= its max on the record
    devices = [
        rv.Harvester(m=M, c_m=C_M, c_e=c_e, k=k, k3=k3)
        for k, k3, c_e in [(57.4, 0.0, 0.5), (57.4, 1e6, 0.3), (-20.0, 1e7, 0.2)]
    ]  # fmt: skip
    for device in devices:
        run = rv.monte_carlo_on_record(device, short_record, segments=2, burn_in=0.0,
                                       substeps=10, record_paths=2, progress=False)  # fmt: skip
        z = run.histories.z
        stroke = float(np.max(np.abs(z)))
        bound = record_harvesting_limit(M, C_M, short_record, stroke)
        # the device's power is a time average over the same record; the bound leaves
        # out the change of stored energy (kinetic + spring), at most this per unit time
        v = run.histories.v
        stored = (
            0.5 * M * np.max(v**2) + 0.5 * abs(device.k) * stroke**2 + 0.25 * device.k3 * stroke**4
        )
        t = short_record.time[-1] - short_record.time[0]
        assert run.power_electrical.mean <= bound + 2 * stored / t
