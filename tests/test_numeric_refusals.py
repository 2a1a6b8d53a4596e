"""Numbers at the edge of float64: a refusal with the real reason, never NaN.

Covers the numeric refusals of :mod:`randvib.analytic.prediction` (no finite
result, float64 blamed only for extreme values),
:mod:`randvib.analytic.statistical_linearisation` (no fixed point, a circuit
time constant beyond float64), :mod:`randvib.models.coupling` (an overflowing
electrical damping), the step advice of :mod:`randvib.montecarlo.step_check`,
and JSON that stays valid (:func:`randvib._io.dumps`).
"""

import json
import math

import pytest
from _cli import error_lines, one_line_error, run

import randvib as rv
from randvib import _io
from randvib.montecarlo.simulation import simulate

BASE = rv.preset("figure9")


@pytest.mark.parametrize(
    "device, fragment",
    [
        (["--m", "1e308"], "no finite result"),
        (["--c-m", "0", "--c-e", "0", "--friction", "coulomb", "--fc", "0"], "no stationary"),
        (["--c-m", "0", "--c-e", "0", "--friction", "none"], "no stationary"),
        (["--k3", "1e308"], "no finite result"),
        (["--psd", "1e308", "--method", "fpk-fast"], "no finite result"),
        (["--m", "1e-300", "--method", "fpk-fast"], "no finite result"),
        (["--excitation", "band-pass", "--f0", "1e308", "--zeta", "0.1"], "no finite result"),
        (["--alpha", "1e308", "--r-load", "1", "--r-coil", "1"], "not a finite number"),
    ],
)
def test_power_never_prints_nan(capsys, device, fragment):
    argv = ["power", "--preset", "figure9", "--psd", "1", *device]
    one_line_error(capsys, argv, fragment)
    one_line_error(capsys, [*argv, "--json"], fragment)


def test_json_output_is_always_valid_json():
    text = _io.dumps({"a": float("nan"), "b": [1.0, float("inf")], "c": {"d": -math.inf}})
    data = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert data["a"] is None and data["b"] == [1.0, None] and data["c"]["d"] is None
    assert set(data["null_reasons"]) == {"a", "b[1]", "c.d"}


def test_step_advice_never_says_dt_at_most_zero(monkeypatch):
    from randvib.montecarlo.step_check import LinearTestSystem

    monkeypatch.setattr(LinearTestSystem, "largest_step", lambda *a, **k: 0.0)
    with pytest.raises(ValueError, match="too large") as info:
        simulate(BASE, 1.0, t_end=10.0, dt=0.5, n_paths=2, progress=False)
    assert "dt <= 0 s" not in str(info.value)


def test_own_refusal_is_not_called_a_float64_overflow(capsys):
    """Found by the fuzz test over the new options: a free mass (k = k3 = 0) under a
    band-pass input was refused with "outside the range float64 can represent"
    appended to the real reason."""
    code, _, err = run(capsys, "power", "--preset", "figure9", "--psd", "1", "--excitation",
                       "band-pass", "--f0", "1", "--zeta", "0.1", "--k", "0", "--k3", "0")  # fmt: skip
    assert code == 2 and "confining potential" in err and "float64" not in err


def test_coupling_overflow_is_a_value_error():
    """Found by the fuzz test: alpha = 1e308 raised OverflowError from alpha**2."""
    from randvib.models.coupling import Resistive

    with pytest.raises(ValueError, match="overflows float64"):
        rv.Harvester.with_coupling(0.02, 0.1, 50.0, Resistive(1e308, 100.0, 10.0))


NARROW_BAND = ["--preset", "figure9", "--psd", "1", "--excitation", "band-pass", "--f0", "1",
               "--zeta", "0.01"]  # fmt: skip


@pytest.mark.parametrize(
    "device",
    [
        # a soft device with a coil at the band's centre: the search's trial c_eq overflows
        [
            "--coupling",
            "inductive",
            "--alpha",
            "1",
            "--r-load",
            "10",
            "--r-coil",
            "1",
            "--inductance",
            "1e-4",
            "--k",
            "1",
            "--k3",
            "10",
        ],  # fmt: skip
        # a double well: a trial k_eq on the solver's floor (an eigenvalue rounding to 0)
        ["--k", "-1", "--k3", "1"],
    ],
    ids=["soft-coil", "double-well"],
)
def test_linearisation_without_a_fixed_point_says_so(capsys, device):
    """At ordinary values these were refused as "outside the range float64 can represent"
    (soft coil) or as the device having "an eigenvalue with non-negative real part
    (0+0j)" (double well): both were the solver's trial steps, not the device."""
    code, _, err = run(capsys, "power", *NARROW_BAND, *device)
    assert code == 2 and len(error_lines(err)) == 1
    assert "statistical linearisation found no fixed point" in err
    assert "`randvib simulate`" in err and "float64" not in err and "0+0j" not in err


def test_float64_is_blamed_only_for_extreme_values():
    from randvib.analytic.prediction import _out_of_range

    ordinary = _out_of_range("fpk", rv.preset("figure9"), 1.0, "LinAlgError: x")
    assert "float64" not in ordinary
    extreme = _out_of_range("fpk", rv.preset("figure9").updated(k3=1e250), 1.0, "LinAlgError: x")
    assert "k3 = 1e+250 is beyond the range this method can compute in float64" in extreme
    tiny = _out_of_range("fpk", rv.preset("figure9"), 1e-300, "LinAlgError: x")
    assert "psd = 1e-300 is beyond" in tiny


def test_optimal_load_of_a_device_that_delivers_nothing_is_refused():
    """Found by the fuzz test with another seed: a coil of 1e308 H passes no current,
    and the 'optimum' was the search's lower bound at 0 W, returned as a result."""
    from randvib.models.coupling import Inductive

    device = rv.Harvester.with_coupling(
        1.0, 0.5, 180.0, Inductive(alpha=50.0, r_load=700.0, r_coil=60.0, inductance=1e308)
    )
    with pytest.raises(ValueError, match="no load resistance in `bounds`.*takes any power"):
        rv.optimal_load_resistance(device, 1.0)


def test_circuit_time_constant_beyond_float64_is_refused():
    """Found by the fuzz test under another seed: R_L C_p = 1e-616 underflowed to 0 and
    ended in a ZeroDivisionError inside statistical linearisation."""
    from randvib.models.coupling import Piezo

    device = rv.Harvester.with_coupling(
        1.0, 0.0, 0.0, Piezo(theta=0.0078125, capacitance=1e-308, r_load=1e-308), k3=1.0
    )
    with pytest.raises(ValueError, match="time constant beyond float64's range"):
        rv.statistical_linearisation(device, rv.BandPass(1.0, 1.0, 1.0))
