"""The whole harvester from the command line: `record`, `identify`, `validate` on channels and
loads, and `--from-fit` (randvib.cli._device, shared by power, simulate, design and record).

Covers the channel options of :mod:`randvib.cli._records`, the identify and
validate commands' circuit options, the validation figure's voltage densities
(:mod:`randvib.identification.plots`) and the saved fit as a device: a fit
passed to `power` is the device written out option by option, so that "which
load should I use" is two commands from a record.
"""

import json

import _electrical as E
import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.identification.result import IdentificationResult

#: A fit of the coil (as identify saves it): the truth, at the first record's load.
COIL_FIT = {**E.COIL}
LOADS = (3.0, 30.0)


def coil_result(**changes) -> IdentificationResult:
    """An identification result holding the coil's truth (cheap: no fit)."""
    parameters = {name: COIL_FIT[name] for name in ("m", "c", "k", "k3", "fc")}
    parameters.update({n: COIL_FIT[n] for n in ("alpha", "r_coil", "inductance")})
    fields = dict(
        model="coulomb", parameters=parameters, free=tuple(parameters)[1:], cost=0.02,
        bounds={}, nfev=0, generations=0, elapsed=0.0, simulations_per_second=0.0,
        message="", record="a, b", coupling="inductive", outputs=("voltage",), r_loads=LOADS,
        records=("a", "b"),
    )  # fmt: skip
    fields.update(changes)
    return IdentificationResult(**fields)


def device_flags(r_load=LOADS[0]):
    """The coil device written out option by option."""
    c = COIL_FIT
    return ["--m", c["m"], "--c-m", c["c"], "--k", c["k"], "--k3", c["k3"], "--friction",
            "coulomb", "--fc", c["fc"], "--coupling", "inductive", "--alpha", c["alpha"],
            "--r-coil", c["r_coil"], "--inductance", c["inductance"], "--r-load", r_load]  # fmt: skip


@pytest.fixture
def saved_fit(tmp_path):
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(coil_result().to_dict()))
    return path


def power_json(capsys, *argv):
    code, out, err = run(capsys, "power", *argv, "--psd", "0.5", "--json")
    assert code == 0, err
    return json.loads(out)


def test_from_fit_is_the_device_written_out(capsys, saved_fit):
    """`power --from-fit` equals `power` with every option of the identified device, at
    the fit's first load and at another (`--r-load` overrides); `--optimal-load` is the
    second of the two commands from a record to "which load should I use"."""
    assert power_json(capsys, "--from-fit", saved_fit) == power_json(capsys, *device_flags())
    other = power_json(capsys, "--from-fit", saved_fit, "--r-load", 10)
    assert other == power_json(capsys, *device_flags(10.0))
    best = power_json(capsys, "--from-fit", saved_fit, "--optimal-load")
    assert best["r_load_optimal"] > 0 and best["power_load_optimal"] >= best["power_load"]


def test_from_fit_round_trips_through_the_saved_json(saved_fit):
    """The saved JSON gives back the device (its coupling at the first load) and the
    fit's loads, channels and identifiability."""
    back = IdentificationResult.from_dict(json.loads(saved_fit.read_text()))
    device = back.harvester()
    assert isinstance(device.electrical, rv.Inductive) and device.electrical.r_load == LOADS[0]
    assert device.c_m == COIL_FIT["c"] and device.friction.fc == COIL_FIT["fc"]
    assert back.r_loads == LOADS and back.outputs == ("voltage",)
    assert back.harvester(r_load=30.0).electrical.r_load == 30.0


def test_from_fit_refusals(capsys, saved_fit, tmp_path):
    one_line_error(
        capsys, ["power", "--from-fit", saved_fit, "--preset", "coulomb-td1", "--psd", "1"],
        "either `--preset` or `--from-fit`",
    )  # fmt: skip
    one_line_error(
        capsys, ["power", "--from-fit", saved_fit, "--theta", "1e-3", "--psd", "1"],
        "`--theta` applies to the piezo coupling",
    )  # fmt: skip
    bad = tmp_path / "bad.json"
    bad.write_text('{"model": "coulomb"}')
    one_line_error(
        capsys, ["power", "--from-fit", bad, "--psd", "1"], "is not a saved identification"
    )
    one_line_error(capsys, ["simulate", "--from-fit", tmp_path / "none.json", "--psd", "1"],
                   "does not exist")  # fmt: skip


#: What each command requires beside the device.
REQUIRED = {"design": ["--vary", "r_load=1:100"], "record": ["--out", "x.csv"]}


@pytest.mark.parametrize("command", ["simulate", "design", "record", "power"])
def test_every_command_with_the_device_options_takes_a_fit(command, saved_fit):
    """The shared device options (randvib.cli._device) give `--from-fit` to every
    command that takes a device: parsed there, the device is the fit's."""
    from randvib.cli import build_parser
    from randvib.cli._device import harvester_from_args

    argv = [command, "--from-fit", str(saved_fit), *REQUIRED.get(command, [])]
    args, _ = build_parser().parse_known_args(argv)
    device = harvester_from_args(args)
    expected = coil_result().harvester()
    assert device.parameters() == expected.parameters()


def test_record_from_a_fit_writes_the_load_voltage(capsys, saved_fit, tmp_path):
    out_csv = tmp_path / "again.csv"
    code, _, err = run(capsys, "record", "--from-fit", saved_fit, "--rms", "1", "--duration",
                       "0.5", "--output-kind", "voltage", "--out", out_csv)  # fmt: skip
    assert code == 0, err
    assert set(rv.read_record(out_csv, outputs={"voltage": "voltage"}).channels) == {
        "base_acceleration", "voltage"}  # fmt: skip


def test_a_column_is_fitted_only_as_its_declared_kind(capsys, tmp_path):
    """A voltage column is never fitted as a displacement: a column named otherwise
    needs its kind, and the kinds pair with the columns in order; a `--weight` names a
    fitted kind."""
    rec = E.record("coil", E.COIL, r_load=3.0, duration=0.3, outputs=("voltage",))
    path = tmp_path / "rig.csv"
    rec.to_frame().rename(columns={"voltage": "V_load"}).to_csv(path, index=False)
    base = ["identify", path, "--model", "coulomb", "--m", "0.0226", "--no-progress"]
    one_line_error(
        capsys, base + ["--output-column", "V_load"], "say what it holds with `--output-kind"
    )
    one_line_error(capsys, base + ["--output-kind", "voltage"], "output column `voltage` not found")
    one_line_error(
        capsys, base + ["--output-kind", "voltage", "--output-kind", "current", "--output-column",
                        "V_load"], "pair in order: got 2 kind(s) and 1 column(s)",
    )  # fmt: skip
    one_line_error(
        capsys, base + ["--output-kind", "voltage", "--output-column", "V_load"],
        "`voltage` output is the circuit's",
    )  # fmt: skip
    one_line_error(
        capsys, base + ["--output-kind", "voltage", "--output-column", "V_load", "--coupling",
                        "resistive", "--r-load", "3"], "cannot determine c, alpha, r_coil",
    )  # fmt: skip
    one_line_error(
        capsys, base + ["--output-kind", "voltage", "--output-column", "V_load", "--coupling",
                        "resistive", "--r-load", "3", "--weight", "current=2"],
        "names 'current', which no record fits",
    )  # fmt: skip


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    """Two voltage records of the coil at two loads (CSV files), 1 % sensor noise."""
    folder = tmp_path_factory.mktemp("rig")
    paths = []
    for i, r_load in enumerate(LOADS):
        rec = E.record("coil", E.COIL, r_load=r_load, seed=i, duration=1.0, noise={"voltage": 0.01})
        paths.append(folder / f"load{i}.csv")
        rec.to_csv(paths[-1], float_format=None)
    return paths


def test_identify_and_validate_voltage_records_at_two_loads(capsys, rig, tmp_path):
    """`identify A.csv B.csv --coupling inductive --r-load 3 --r-load 30 --output-kind
    voltage`, the search boxed near the truth to keep it short; the saved fit then
    validates on the records: J and the RMS error in volts per record, at the noise's
    level (1 % of each record's voltage), and its figure has the voltage's density."""
    saved = tmp_path / "coil.json"
    box = [f"{n}={0.8 * COIL_FIT[n]}:{1.25 * COIL_FIT[n]}" for n in ("c", "k", "fc", "alpha",
           "r_coil", "inductance")] + [f"k3={0.8 * COIL_FIT['k3']}:{1.25 * COIL_FIT['k3']}"]  # fmt: skip
    code, out, err = run(
        capsys, "identify", *rig, "--model", "coulomb", "--m", COIL_FIT["m"], "--coupling",
        "inductive", "--r-load", LOADS[0], "--r-load", LOADS[1], "--output-kind", "voltage",
        "--popsize", 10, "--generations", 4, "--no-progress", "--save", saved,
        *[flag for b in box for flag in ("--bounds", b)],
    )  # fmt: skip
    assert code == 0, err
    assert "the records fix: c, k, k3, fc, alpha, r_coil, inductance" in out
    assert "records at 2 loads split" in out and "voltage_offset[1]" in out
    fit = json.loads(saved.read_text())
    assert fit["coupling"] == "inductive" and fit["r_loads"] == list(LOADS)
    figure = tmp_path / "figures"
    code, out, err = run(capsys, "validate", saved, *rig, "--r-load", LOADS[0], "--r-load",
                         LOADS[1], "--json", "--plot", figure)  # fmt: skip
    assert code == 0, err
    rows = json.loads(out)["records"]
    for row, path in zip(rows, rig, strict=True):
        volts = rv.read_record(path, outputs={"voltage": "voltage"})["voltage"]
        channel = row["channels"]["voltage"]
        assert channel["unit"] == "V" and row["r_load"] in LOADS
        assert channel["rms_error"] == pytest.approx(0.01 * np.std(volts), rel=0.2)
        assert channel["cost"] == pytest.approx(100 * 0.01**2, rel=0.2)
    assert len(list(figure.glob("*.png"))) == 2


def test_validation_figure_shows_the_voltage_density_beside_the_time_history():
    """The figure's panels: the voltage's time history and residual, its density
    (measured and simulated: the spike at 0 V is there when the magnet sticks)."""
    from randvib.identification.plots import figure_fit

    rec = E.record("coil", E.COIL, r_load=3.0, duration=0.5, outputs=("voltage",))
    device = coil_result().harvester()
    pred = rv.predict_record(device, rec, outputs=("voltage",), hold="linear")
    assert pred.costs["voltage"] < 1e-6  # the truth: J ~ 0 against the generator
    fig = figure_fit(pred, validation=True)
    labels = [ax.get_xlabel() for ax in fig.axes] + [ax.get_ylabel() for ax in fig.axes]
    assert any(label.startswith("load voltage V (") for label in labels)
    assert sum(label.startswith("density (1/") for label in labels) == 1
