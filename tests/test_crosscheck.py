"""Analytic answers against Monte Carlo: the cross-check campaign's worst failures warn or refuse.

Covers the validity limits of randvib.analytic.statistical_linearisation
(friction and cubic-stiffness shares off the white-noise path, double wells)
and randvib.analytic.fokker_planck (barrier depths with friction), set from
tests/calibration/crosscheck.py (260 sampled devices and 120 double wells with
friction against Monte Carlo). The devices below are the campaign's cases
(seeded draws) with their parameters written out; each failure was an answer
without a warning off by more than 10 % + the Monte Carlo 95 % interval.
"""

import warnings

import pytest

import randvib as rv
from randvib.analytic.statistical_linearisation import LinearisationValidityWarning

M = 0.0226  # kg, the conventions' magnet mass


def resistive(c_m, c_e, k, k3, friction=None):
    return rv.Harvester(m=M, c_m=c_m, c_e=c_e, k=k, k3=k3, friction=friction)


# ------------------------------------------------------------ former silent failures
#: (device, psd, method, what it gave against Monte Carlo before the limits)
REFUSED = {
    "fpk-fast, double well with heavy Coulomb friction (4.83x)": (
        resistive(0.0134869, 0.00690407, -93.6893, 285188.0, rv.Coulomb(0.0189778)),
        0.216196,
        "fpk-fast",
    ),
    "fpk-fast, double well with tanh friction (65x)": (
        resistive(0.00228299, 0.00410859, -31.9746, 2502110.0, rv.Tanh(0.0156644, 43.2325)),
        0.0072493,
        "fpk-fast",
    ),
    "fpk-fast, shallow double well with friction taking 93 % of the dissipation (1.19x)": (
        resistive(0.00706162, 0.000666279, -94.3017, 43247126.4, rv.Tanh(0.00447603, 51.7133)),
        0.0188833,
        "fpk-fast",
    ),
    "fpk, double well 10.6 m E[v^2] deep with Coulomb friction (1.41x)": (
        resistive(0.00197351, 0.00239586, -95.0131, 157038.0, rv.Coulomb(0.00262746)),
        0.0463417,
        "fpk",
    ),
}


@pytest.mark.parametrize("name", list(REFUSED))
def test_former_silent_failures_of_the_fpk_solvers_are_refused(name):
    device, psd, method = REFUSED[name]
    with pytest.raises(ValueError, match=f"^method='{method}' .*double wells.*: use "):
        rv.predict(device, psd, method)


WARNED = {
    "double well under Kanai-Tajimi input (46.6x)": (
        resistive(0.110837, 0.00670912, -179.455, 3806040.0, rv.Tanh(0.00649625, 184.702)),
        rv.KanaiTajimi(0.743011, 7.15461, 0.183496),
        "double well",
    ),
    "double well with a piezo element under white noise (11.6x)": (
        rv.Harvester.with_coupling(
            m=M, c_m=0.110655, k=-22.9248, k3=32878.1, friction=rv.Coulomb(0.00996256),
            coupling=rv.Piezo(0.00017381, 5e-08, 3280460.0),
        ),
        0.376011,
        "double well",
    ),
    "hardening spring under band-pass input (0.85x)": (
        resistive(0.0152761, 0.0983967, 24.6428, 35088300.0),
        rv.BandPass(0.389313, 5.47156, 0.0518544),
        "cubic spring takes",
    ),
    "hardening spring with a piezo element under Kanai-Tajimi input (0.52x)": (
        rv.Harvester.with_coupling(
            m=M, c_m=0.127372, k=143.418, k3=323171000000.0, friction=rv.Coulomb(0.000145845),
            coupling=rv.Piezo(0.000336196, 5e-08, 115230.0),
        ),
        rv.KanaiTajimi(0.00258484, 6.46389, 0.147082),
        "cubic spring takes",
    ),
    "Coulomb friction with a piezo element under white noise (0.60x)": (
        rv.Harvester.with_coupling(
            m=M, c_m=0.0316175, k=26.7386, k3=15951900000.0, friction=rv.Coulomb(0.0439903),
            coupling=rv.Piezo(9.82247e-05, 5e-08, 850164.0),
        ),
        0.0161785,
        "friction takes",
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", list(WARNED))
def test_former_silent_failures_of_linearisation_warn(name):
    device, psd, words = WARNED[name]
    with pytest.warns(LinearisationValidityWarning, match=words):
        rv.predict(device, psd, "linearisation")


# ------------------------------------------------------------ well inside: silent and right
#: (device, psd, methods answering without a warning, Monte Carlo settings)
INSIDE = {
    "Duffing with light Coulomb friction, white noise": (
        resistive(0.00320195, 0.0716114, 75.3828, 1113560187.0, rv.Coulomb(0.000130977)),
        0.00107388,
        ("linearisation", "averaging", "fpk-fast", "fpk"),
        dict(dt=0.00128, t_end=22.0, burn_in=2.0, n_paths=32, control_variates=True),
    ),
    "shallow double well with Coulomb friction, white noise": (
        resistive(0.0127668, 0.0891552, -168.586, 712308000.0, rv.Coulomb(0.000674175)),
        0.00861356,
        ("fpk-fast", "fpk"),
        dict(dt=0.00093, t_end=22.0, burn_in=2.0, n_paths=32, control_variates=True),
    ),
    "soft Duffing under band-pass input": (
        resistive(0.0632182, 0.0287529, 64.0091, 96074.7),
        rv.BandPass(0.141721, 6.59308, 0.145517),
        ("linearisation",),
        dict(dt=0.002, t_end=22.0, burn_in=2.0, n_paths=208),
    ),
}


@pytest.mark.parametrize("name", list(INSIDE))
def test_answers_well_inside_the_limits_are_silent_and_within_ten_percent(name):
    device, psd, methods, settings = INSIDE[name]
    mc = rv.simulate(device, psd, seed=3, progress=False, threads=1, **settings).power_electrical
    for method in methods:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no warning of any kind
            power = rv.predict(device, psd, method).power_electrical
        # the bar of the campaign: 10 % plus the Monte Carlo 95 % half-width
        assert abs(power - mc.mean) <= 0.10 * mc.mean + mc.ci95, (method, power, mc)
