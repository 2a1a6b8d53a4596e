"""A circuit state under synthesised (band-limited) base acceleration, in Monte Carlo.

The linear device (k3 = 0, no friction) with a coil's current or a piezo's
voltage as a state, driven by the stationary Gaussian synthesis of a
band-limited spectrum: the response is Gaussian and linear, so statistical
linearisation (the spectral integral with the circuit in the transfer
function) is exact, an independent route to E[P_e], E[z'^2] and the
displacement variance. The scheme's time-step bias is bounded by
:func:`step_bias` (the augmented device with the circuit, driven like white
noise), below 1e-3 here against the 5 % the test is powered to detect; the
synthesis carries the exact power of each frequency cell.

Calibration (``NUMBA_NUM_THREADS=1 python tests/calibration/coupling_synthesised.py
40``, seeds 1000-1039), z mean / SD / largest |z| (smallest power margin, SE):
inductive P_e -0.04 / 0.92 / 2.66 (6.27), E[v^2] -0.04 / 0.92 / 2.68 (6.35),
E[z^2] -0.04 / 0.92 / 2.64 (6.31); piezo P_e -0.11 / 0.94 / 2.19 (9.25),
E[v^2] -0.11 / 0.94 / 2.18 (9.42), E[z^2] -0.11 / 0.94 / 2.18 (9.28).

Covers a circuit state of :mod:`randvib.models.coupling` driven by the synthesised input
of :mod:`randvib.montecarlo.driven`.
"""

import pytest
from _stats import assert_matches

import randvib as rv
from randvib.montecarlo.simulation import simulate
from randvib.montecarlo.step_check import step_bias

M, C_M, K = 0.0226, 0.05, 57.4
COUPLINGS = {
    "inductive": rv.Inductive(alpha=0.1992, r_load=1.0, r_coil=0.48, inductance=0.05),
    "piezo": rv.Piezo(theta=1e-3, capacitance=1e-7, r_load=1e5),
}
BAND = rv.BandLimited(1.0, 4.0, 20.0)  # around the 8.02 Hz resonance
DT = 5e-4


def case_band_limited_circuit(name, seed, n_paths=1024):
    """Heun, 1024 paths x 14 s after 2 s burn-in: P_e (from the circuit state), E[v^2], E[z^2]."""
    h = rv.Harvester.with_coupling(M, C_M, K, COUPLINGS[name])
    assert step_bias("heun", h, BAND, DT) < 1e-3
    exact = rv.statistical_linearisation(h, BAND)
    r = simulate(h, BAND, t_end=16.0, dt=DT, n_paths=n_paths, burn_in=2.0, seed=seed,
                 progress=False)  # fmt: skip
    return [
        ("P_e", r.power_electrical, exact.power_electrical, 0.0, 0.05),
        ("E[v^2]", r.velocity_variance, exact.velocity_variance, 0.0, 0.05),
        ("E[z^2]", r.displacement_variance, exact.displacement_variance, 0.0, 0.05),
    ]


@pytest.mark.parametrize("name", COUPLINGS)
def test_circuit_state_under_band_limited_input_matches_linearisation(name):
    for what, stat, ref, bias, detect in case_band_limited_circuit(name, seed=7):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=f"{name} {what}")
