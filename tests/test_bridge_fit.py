"""A fit made behind a diode bridge, end to end: saved, validated and used as a device.

Covers the saved identification's ``rectifier`` (:mod:`randvib.identification.result`,
``saved_rectifier`` and ``bridge_from_parameters`` of
:mod:`randvib.identification.circuit`), ``randvib validate`` through the file's
bridge (:mod:`randvib.cli.validate`) and ``--from-fit`` of a bridged fit in
``power``, ``simulate``, ``design`` and ``record`` (:mod:`randvib.cli._device`):
identify -> save -> validate / power / simulate, two commands from a record to
an answer, and never a bridge silently dropped.

The record is the command line's own (``randvib record --rectifier bridge``, 1 s,
2 mV of sensor noise on the storage capacitor's voltage); the fit is a tiny
search (8 x 2 generations and the polish), as the other CLI tests keep theirs.
"""

import json

import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.cli import build_parser
from randvib.cli._device import harvester_from_args
from randvib.identification.prediction import validate
from randvib.identification.result import IdentificationResult

#: The paper's mechanics with a coil strong enough to pass the diodes' drops
#: (tests/test_record_bridge.py's STORAGE).
DEVICE = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, alpha=1.0, r_coil=2.0)
BRIDGE = {"v_diode": 0.2, "storage_capacitance": 2e-3}
R_LOAD = 50.0
NOISE = 0.002  # V, RMS on the voltage channel
SAMPLES = 1000


@pytest.fixture(scope="module")
def bridged_fit(tmp_path_factory):
    """(record CSV, saved fit) of ``record --rectifier bridge`` and ``identify --rectifier
    bridge --save`` (module-scoped: read only by the tests)."""
    from randvib.cli import main

    folder = tmp_path_factory.mktemp("bridge_fit")
    data, fit = folder / "bridge.csv", folder / "fit.json"
    d = DEVICE
    record = ["record", "--m", d["m"], "--c-m", d["c"], "--k", d["k"], "--k3", d["k3"],
              "--coupling", "inductive", "--alpha", d["alpha"], "--r-coil", d["r_coil"],
              "--rectifier", "bridge", "--v-diode", BRIDGE["v_diode"], "--storage-capacitance",
              BRIDGE["storage_capacitance"], "--r-load", R_LOAD, "--output-kind", "voltage",
              "--noise", f"voltage={NOISE}", "--rms", "4", "--duration", "1", "--seed", "3",
              "--out", data]  # fmt: skip
    identify = ["identify", data, "--model", "viscous", "--m", d["m"], "--coupling", "inductive",
                "--r-load", R_LOAD, "--rectifier", "bridge", "--v-diode", BRIDGE["v_diode"],
                "--storage-capacitance", BRIDGE["storage_capacitance"], "--output-kind",
                "voltage", "--fix", "k3=70742", "--fix", "r_coil=2", "--fix", "inductance=0",
                "--fix", "voltage_offset=0", "--bounds", "k=20:200", "--bounds", "alpha=0.5:2",
                "--bounds", "c=0.01:0.2", "--popsize", "8", "--generations", "2",
                "--no-progress", "--save", fit]  # fmt: skip
    for argv in (record, identify):
        assert main([str(a) for a in argv]) == 0
    return data, fit


def test_a_bridged_fit_saves_its_bridge_and_validate_scores_through_it(capsys, bridged_fit):
    """The saved fit holds the bridge as data, and ``validate`` on the training record
    simulates through it: its J is the fit's J (the same cost at the same parameters,
    minimised over the same start: equal to within the least-squares polish's relative
    tolerance, 1e-8 on the cost, within 1e-6 here; measured 1.2e-12), its RMS error in volts the sensor's 2 mV to within 4 chi-squared
    spreads of 1000 samples (4 / sqrt(2000) = 9 %). The same coil without its bridge (a
    linear coil at 50 ohm, what dropping it would score) misses by far more (J = 906)."""
    data, path = bridged_fit
    saved = json.loads(path.read_text())
    assert saved["rectifier"] == {"kind": "bridge", **BRIDGE}
    code, out, err = run(capsys, "validate", path, data, "--offsets", "given", "--json")
    assert code == 0, err
    (row,) = json.loads(out)["records"]
    assert row["r_load"] == R_LOAD
    assert row["cost"] == pytest.approx(saved["cost"], rel=1e-6)
    volts = row["channels"]["voltage"]
    assert volts["unit"] == "V"
    assert volts["rms_error"] == pytest.approx(NOISE, rel=4 / np.sqrt(2 * SAMPLES))
    # the same fit scored without its bridge (its note too, else it is refused)
    unbridged = IdentificationResult.from_dict({**saved, "rectifier": None, "notes": []})
    (without,) = validate(
        unbridged.harvester(), [rv.read_record(data, outputs={"voltage": "voltage"})],
        measurement=unbridged.measurement, outputs=("voltage",), offsets="given",
    )  # fmt: skip
    assert without.cost > 10 * row["cost"]


def test_validate_takes_the_bridge_from_the_file_and_refuses_a_contradiction(
    capsys, bridged_fit, tmp_path
):
    """Bridge flags that repeat the file's are accepted (the same J); one that differs
    is refused in one line; a file saved before the ``rectifier`` field, its notes naming
    the bridge, is refused rather than scored without it (validate and --from-fit)."""
    data, path = bridged_fit
    code, same, err = run(capsys, "validate", path, data, "--rectifier", "bridge", "--v-diode",
                          "0.2", "--storage-capacitance", "2e-3", "--offsets", "given", "--json")  # fmt: skip
    assert code == 0, err
    code, plain, err = run(capsys, "validate", path, data, "--offsets", "given", "--json")
    assert json.loads(same)["records"] == json.loads(plain)["records"]
    one_line_error(capsys, ["validate", path, data, "--v-diode", "0.3"], "contradicts")
    one_line_error(capsys, ["validate", path, data, "--battery", "0.3"], "contradicts")
    old = tmp_path / "old.json"
    saved = json.loads(path.read_text())
    saved.pop("rectifier")
    old.write_text(json.dumps(saved))
    one_line_error(capsys, ["validate", old, data], 'saves no "rectifier" field')
    one_line_error(
        capsys, ["power", "--from-fit", old, "--psd", "0.5"], 'saves no "rectifier" field'
    )


@pytest.mark.parametrize("command", ["simulate", "design", "record", "power"])
def test_from_fit_gives_every_command_the_bridge(command, bridged_fit):
    """The device of ``--from-fit`` is the fitted coupling through the fit's bridge, at
    the record's load, in every command that takes a device (parsed there)."""
    _, path = bridged_fit
    required = {"design": ["--vary", "r_load=1:100"], "record": ["--out", "x.csv"]}
    args, _ = build_parser().parse_known_args(
        [command, "--from-fit", str(path), *required.get(command, [])]
    )
    bridge = harvester_from_args(args).electrical
    fitted = json.loads(path.read_text())["parameters"]
    assert isinstance(bridge, rv.BridgeCoil)
    assert (bridge.alpha, bridge.r_coil) == (fitted["alpha"], fitted["r_coil"])
    assert (bridge.v_diode, bridge.storage_capacitance, bridge.r_load) == (0.2, 2e-3, R_LOAD)


def test_power_and_simulate_from_a_bridged_fit(capsys, bridged_fit):
    """``power --from-fit`` predicts the bridge by its own method (its outputs overridden:
    a battery at 0 V and ideal diodes, where the closure applies), finds the optimum by
    Monte Carlo over ``--optimal-bounds``, and where the closure does not take the
    fitted bridge says so in one line naming what to use; ``simulate --from-fit``
    describes the bridge and reports the stored and diode powers only a bridge has."""
    _, path = bridged_fit
    code, out, err = run(capsys, "power", "--from-fit", path, "--psd", "0.5", "--battery", "0",
                         "--v-diode", "0", "--json")  # fmt: skip
    assert code == 0, err
    closure = json.loads(out)
    assert (closure["method"], closure["coupling"]) == ("bridge-closure", "inductive bridge")
    one_line_error(capsys, ["power", "--from-fit", path, "--psd", "0.5"], "Monte Carlo")
    one_line_error(capsys, ["power", "--from-fit", path, "--psd", "0.5", "--optimal-load"],
                   "`--optimal-bounds LOW HIGH`")  # fmt: skip
    one_line_error(capsys, ["power", "--from-fit", path, "--psd", "0.5", "--c-e", "0.1"],
                   "`--c-e` cannot replace it")  # fmt: skip
    code, out, err = run(capsys, "power", "--from-fit", path, "--psd", "0.5", "--optimal-load",
                         "--optimal-bounds", "10", "200", "--optimal-paths", "2",
                         "--optimal-t-end", "2.5", "--optimal-grid", "3", "--json",
                         "--no-progress")  # fmt: skip
    assert code == 0, err
    best = json.loads(out)
    assert best["coupling"] == "inductive bridge" and 10 <= best["r_load_optimal"] <= 200
    code, out, err = run(capsys, "simulate", "--from-fit", path, "--psd", "0.5", "--paths", "4",
                         "--t-end", "0.5", "--burn-in", "0.1")  # fmt: skip
    assert code == 0, err
    assert "inductive bridge coupling" in out and "storage_capacitance 0.002 F" in out
    for row in ("power_stored", "power_diode_loss"):
        assert row in out


def coil_fit(**changes) -> IdentificationResult:
    """A saved result holding the coil's values (cheap: no fit)."""
    parameters = {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 70742.0, "alpha": 1.0,
                  "r_coil": 2.0, "inductance": 0.0}  # fmt: skip
    fields = dict(
        model="viscous", parameters=parameters, free=("c", "k", "alpha"), cost=0.05, bounds={},
        nfev=0, generations=0, elapsed=0.0, simulations_per_second=0.0, message="",
        record="r", coupling="inductive", outputs=("current",), r_loads=(R_LOAD,), records=("r",),
    )  # fmt: skip
    fields.update(changes)
    return IdentificationResult(**fields)


def test_saved_rectifier_round_trips_and_old_files_load_as_before():
    """A battery's bridge round-trips (no load: a battery has none); a fit without a
    bridge saves no ``rectifier`` and loads as before; a malformed one is refused."""
    battery = coil_fit(rectifier={"v_diode": 0.1, "battery": 0.1})
    saved = battery.to_dict()
    assert saved["rectifier"] == {"kind": "bridge", "v_diode": 0.1, "battery": 0.1}
    back = IdentificationResult.from_dict(json.loads(json.dumps(saved)))
    device = back.harvester()
    assert isinstance(device.electrical, rv.BridgeCoil)
    assert (device.electrical.battery, device.electrical.r_load) == (0.1, None)
    plain = coil_fit().to_dict()
    assert "rectifier" not in plain
    assert isinstance(IdentificationResult.from_dict(plain).harvester().electrical, rv.Inductive)
    for bad in ({"kind": "diode"}, {"kind": "bridge", "v_diode": 0.1},
                {"kind": "bridge", "battery": 1, "storage_capacitance": 1e-3}):  # fmt: skip
        with pytest.raises(ValueError, match="rectifier"):
            IdentificationResult.from_dict({**plain, "rectifier": bad})


def test_validate_through_a_battery_bridge(capsys, tmp_path):
    """``validate`` of a fit behind a battery scores its charging current (the row has no
    load: a battery has none): the true device on its own noiseless record scores J ~ 0
    (the same record simulation, J the start estimate's residual only: measured 1.8e-8),
    and with the battery at 0.2 V instead of 0.1 V far more (measured 104). A fit made
    without a bridge is scored behind the one the flags give (the same J)."""
    data = tmp_path / "battery.csv"
    d = DEVICE
    code, _, err = run(capsys, "record", "--m", d["m"], "--c-m", d["c"], "--k", d["k"], "--k3",
                       d["k3"], "--coupling", "inductive", "--alpha", d["alpha"], "--r-coil",
                       d["r_coil"], "--rectifier", "bridge", "--v-diode", "0.1", "--battery",
                       "0.1", "--output-kind", "current", "--rms", "4", "--duration", "0.5",
                       "--seed", "5", "--out", data)  # fmt: skip
    assert code == 0, err
    costs = {}
    for volts in (0.1, 0.2):
        fit = tmp_path / f"fit{volts}.json"
        fit.write_text(json.dumps(coil_fit(rectifier={"v_diode": 0.1, "battery": volts}).to_dict()))
        code, out, err = run(capsys, "validate", fit, data, "--offsets", "given", "--json")
        assert code == 0, err
        (row,) = json.loads(out)["records"]
        assert "r_load" not in row
        costs[volts] = row["cost"]
    assert costs[0.1] < 1e-6 and costs[0.2] > 1.0
    # a fit made without a bridge, scored behind the one the flags give: the same J
    plain = tmp_path / "plain.json"
    plain.write_text(json.dumps(coil_fit().to_dict()))
    code, out, err = run(capsys, "validate", plain, data, "--offsets", "given", "--json",
                         "--rectifier", "bridge", "--v-diode", "0.1", "--battery", "0.1")  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["records"][0]["cost"] == costs[0.1]
    one_line_error(capsys, ["validate", plain, data, "--rectifier", "bridge"], "exactly one output")
