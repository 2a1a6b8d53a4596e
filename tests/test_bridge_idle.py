"""A diode bridge that never conducts says so (issue 35, item 4).

:func:`randvib.simulate` warns (:class:`randvib.montecarlo.bridge_step.BridgeIdleWarning`)
with the transducer's RMS voltage against the threshold V_out + 2 V_d and what
would help (:meth:`randvib.models.rectifier.Rectified.idle_advice`);
:func:`randvib.simulated_dc_optimum`, ``randvib power --optimal-load`` and
:func:`randvib.design` refuse an optimum of zero power.
"""

from __future__ import annotations

import math
import re
import warnings

import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.montecarlo.bridge_step import BridgeIdleWarning
from randvib.montecarlo.sweep import SweepSettings

M, C_M, K, S = 0.0226, 0.05, 57.4, 1.0
#: The issue's device: the paper's coil into a 3.7 V battery through 0.3 V diodes.
IDLE = rv.BridgeCoil(alpha=0.1992, r_coil=0.48, v_diode=0.3, battery=3.7)
DEVICE = ["--m", M, "--c-m", C_M, "--k", K, "--psd", S, "--coupling", "inductive",
          "--rectifier", "bridge", "--alpha", 0.1992, "--r-coil", 0.48, "--v-diode", 0.3,
          "--battery", 3.7]  # fmt: skip


def test_advice_names_the_rms_the_threshold_and_what_would_help():
    # an idle bridge leaves the linear device without electrical damping:
    # E[z'^2] = S m / (4 c_m) exactly, so the EMF's RMS is alpha sqrt(S m / (4 c_m))
    rms = 0.1992 * math.sqrt(S * M / (4 * C_M))
    text = IDLE.idle_advice(rms)
    assert f"RMS {rms:.3g} V" in text and "V_b + 2 V_d = 4.3 V" in text
    assert f"{4.3 / rms:.3g} times its RMS" in text
    assert "more turns" in text and "step-up transformer or converter" in text
    assert "lower-drop rectifier" in text  # 2 V_d = 0.6 V alone is 9 times the RMS
    # diodes that are not the obstacle are not blamed
    low_drop = rv.BridgeCoil(alpha=0.1992, r_coil=0.48, v_diode=0.01, battery=3.7)
    assert "lower-drop" not in low_drop.idle_advice(rms)
    piezo = rv.BridgePiezo(theta=1e-3, capacitance=1e-7, v_diode=0.3, storage_capacitance=1e-5,
                           r_load=1e5)  # fmt: skip
    assert "V_C + 2 V_d = 0.6 V" in piezo.idle_advice(0.1) and "theta" in piezo.idle_advice(0.1)


def test_simulate_warns_when_the_bridge_never_conducts_and_not_otherwise():
    device = rv.Harvester.with_coupling(M, C_M, K, IDLE)
    with pytest.warns(BridgeIdleWarning, match="never conducted") as seen:
        result = rv.simulate(device, S, t_end=2.0, burn_in=0.5, dt=2e-4, n_paths=16,
                             progress=False)  # fmt: skip
    assert result.power_stored.mean == 0.0
    # the RMS it quotes is the run's own alpha sqrt(E[z'^2])
    quoted = float(re.search(r"RMS ([0-9.e-]+) V", str(seen[0].message)).group(1))
    assert quoted == pytest.approx(0.1992 * math.sqrt(result.velocity_variance.mean), rel=2e-3)
    conducting = rv.Harvester.with_coupling(
        M, C_M, K, rv.BridgeCoil(alpha=0.1992, r_coil=0.48, v_diode=0.01, battery=0.03)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", BridgeIdleWarning)
        assert rv.simulate(conducting, S, t_end=2.0, burn_in=0.5, dt=2e-4, n_paths=16,
                           progress=False).power_stored.mean > 0  # fmt: skip


def test_cli_simulate_prints_the_warning(capsys):
    code, out, err = run(capsys, "simulate", *DEVICE, "--paths", 8, "--t-end", 1.5, "--burn-in",
                         0.5, "--dt", 2e-4, "--no-progress")  # fmt: skip
    assert code == 0
    assert "randvib simulate: warning: the bridge never conducted" in err
    assert "power_stored" in out


def test_an_optimum_of_zero_power_is_refused():
    device = rv.Harvester.with_coupling(M, C_M, K, IDLE)
    with pytest.raises(ValueError, match=r"no battery voltage in \[0, 4\] V stores power.*never "
                       r"conducted.*V_b \+ 2 V_d = 0.6 V"):  # fmt: skip
        rv.simulated_dc_optimum(device, S, (0.0, 4.0), n_grid=3, t_end=2.5, n_paths=4,
                                progress=False)  # fmt: skip


def test_cli_power_optimal_load_refuses_zero_power(capsys):
    one_line_error(capsys, ["power", *DEVICE, "--optimal-load", "--optimal-bounds", 0, 4,
                            "--optimal-grid", 3, "--optimal-paths", 2, "--optimal-t-end", 2.5,
                            "--no-progress"], "never conducted")  # fmt: skip


def test_design_of_an_idle_bridge_is_refused():
    device = rv.Harvester.with_coupling(M, C_M, K, IDLE, stroke=0.05)
    settings = SweepSettings(dt=2e-4, window=0.5, burn_in=2.0, min_paths=8, max_paths=8,
                             control_variates=False)  # fmt: skip
    with pytest.raises(ValueError, match="has no optimum.*never conducted"):
        rv.design(device, S, {"battery": (3.0, 4.0)}, objective="stored", settings=settings,
                  workers=1, refine=False)  # fmt: skip
