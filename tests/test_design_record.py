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
from randvib.montecarlo.sweep import SweepSettings

M, C_M = 0.0226, 0.049
FS = 200.0  #: record sample rate (Hz)


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
