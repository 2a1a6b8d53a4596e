"""Optimal load search: an interval derived from the device, and an answer saying where it lies.

The references are exact: the white-noise optima of the linear device
(:meth:`randvib.models.coupling.Coupling.white_noise_optimal_load`, from the
Lyapunov solution) and, for a coil with R_C = 0, the friction-free load power
c_e/(c_m + c_e) S m/4, which rises monotonically as R_L -> 0 (no interior
maximum).

Covers :mod:`randvib.analytic.prediction` (``optimal_load_resistance``,
``load_search_bounds``) and the ``--optimal-load`` option of :mod:`randvib.cli.power`.
"""

import json

import numpy as np
import pytest
from _cli import run

import randvib as rv
from randvib.analytic.prediction import LoadBoundWarning, load_search_bounds

M, C_M, K = 0.0226, 0.05, 57.4
#: the issue's piezo element: theta 1e-4 N/V, C_p 1 nF; its white-noise
#: optimum on this device is sqrt(m / (C_p (C_p k + theta^2))) = 18.3 MOhm,
#: beyond a fixed 1 MOhm search bound
PIEZO = rv.Piezo(theta=1e-4, capacitance=1e-9, r_load=1e6)


def test_piezo_optimum_beyond_a_megaohm_is_found_interior():
    """The search finds the exact optimum (to the 3e-5 of the linearisation's fixed point)."""
    device = rv.Harvester.with_coupling(M, C_M, K, PIEZO)
    exact = PIEZO.white_noise_optimal_load(M, C_M, K)
    assert exact > 1e7
    best = rv.optimal_load_resistance(device, 0.5)
    assert best.location == "interior" and best.interior
    assert best.r_load == pytest.approx(exact, rel=3e-5)
    lo, hi = best.bounds
    assert lo < exact / 100 and hi > exact * 100
    # the optimum takes at least the power of the user's own load
    assert best.power >= rv.expected_power(device, 0.5, into="load")


def test_coil_without_resistance_reports_the_lower_bound_and_warns():
    """With R_C = 0, P_L = c_e/(c_m + c_e) S m/4 rises as R_L -> 0: no maximum to return."""
    device = rv.Harvester.from_electrical(m=M, c_m=C_M, k=K, alpha=0.2, r_load=1.0, r_coil=0.0)
    with pytest.warns(LoadBoundWarning, match="lower bound"):
        best = rv.optimal_load_resistance(device, 0.5)
    assert best.location == "lower bound" and not best.interior
    assert best.r_load == pytest.approx(best.bounds[0], rel=1e-12)
    # the best load in the bounds, and below the supremum m S / 4 (c_e -> infinity)
    c_e = 0.2**2 / best.r_load
    assert best.power == pytest.approx(c_e / (C_M + c_e) * 0.5 * M / 4, rel=1e-9)
    assert best.power < 0.5 * M / 4


def test_search_interval_is_centred_on_the_device():
    """Matched impedance R_C + alpha^2/c_m of a coil lies decades inside the interval."""
    device = rv.Harvester.from_electrical(m=M, c_m=C_M, k=K, alpha=0.2, r_load=1.0, r_coil=0.5)
    lo, hi = load_search_bounds(device)
    matched = 0.5 + 0.2**2 / C_M
    assert lo <= matched / 1e4 and hi >= matched * 1e4
    best = rv.optimal_load_resistance(device, 0.5)
    assert best.interior
    assert best.r_load == pytest.approx(rv.optimal_load_resistance_linear(C_M, 0.2, 0.5), rel=3e-5)


def test_cli_optimal_load_states_where_it_lies(capsys):
    """``--optimal-load`` beyond 1 MOhm for the piezo device; the R_C = 0 bound said on stderr."""
    piezo = ["--m", M, "--c-m", C_M, "--k", K, "--coupling", "piezo", "--theta", "1e-4",
             "--capacitance", "1e-9", "--r-load", "1e6", "--psd", "0.5"]  # fmt: skip
    code, out, err = run(capsys, "power", *piezo, "--optimal-load", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert got["r_load_optimal_location"] == "interior"
    exact = PIEZO.white_noise_optimal_load(M, C_M, K)
    assert got["r_load_optimal"] == pytest.approx(exact, rel=3e-5)
    assert got["power_load_optimal"] >= got["power_load"]
    coil = ["--m", M, "--c-m", C_M, "--k", K, "--alpha", "0.2", "--r-load", "1",
            "--r-coil", "0", "--psd", "0.5"]  # fmt: skip
    code, out, err = run(capsys, "power", *coil, "--optimal-load", "--json")
    assert code == 0, err
    got = json.loads(out)
    assert got["r_load_optimal_location"] == "lower bound"
    assert "warning:" in err and "lower bound" in err and "--r-coil = 0" in err
    assert np.isfinite(got["power_load_optimal"])
