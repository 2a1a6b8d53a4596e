"""What a new user meets in the first hour: results that convert, messages that lead.

Covers the step check's refusal (:mod:`randvib.montecarlo.step_check`), file
modes of written outputs (:mod:`randvib._io`, see also tests/test_output_files.py),
:class:`randvib.statistics.Statistic`'s conversions, the printed tables and
frames of :mod:`randvib.analytic.power_prediction`, broadcasting in
:mod:`randvib.analytic.prediction` and :mod:`randvib.analytic.statistical_linearisation`,
bistable devices by their wells (:mod:`randvib.models.potential`,
:mod:`randvib.models.harvester`), and the CLI's options and refusals
(:mod:`randvib.cli.power`, :mod:`randvib.cli._device`, :mod:`randvib.cli._excitation`,
:mod:`randvib.cli._output`, :mod:`randvib.cli.validate`, :mod:`randvib.cli.design`); the
printed tables of :mod:`randvib.identification.result` and
:mod:`randvib.harvester_design.result`, with units from :mod:`randvib.quantities`.
"""

import warnings

import pytest
from _cli import one_line_error
from _cli import run as run_cli

import randvib as rv


def test_unstable_step_is_called_unstable_not_off_by_inf():
    """Euler-Maruyama at a step beyond its stability limit: the refusal says unstable,
    gives a finite step, and no scipy warning comes before it."""
    h = rv.Harvester(m=0.0226, c_m=0.001, c_e=0.0, k=5740.0, k3=7e4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError) as info:
            rv.simulate(h, 0.005, scheme="euler-maruyama", dt=5e-4, t_end=1.0, n_paths=2)
    message = str(info.value)
    assert "unstable" in message and "inf" not in message, message
    assert "use dt <=" in message


POWER = ["power", "--preset", "coulomb-td1", "--psd", "0.005"]


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--excitation", "kanai-tajimi", "--zeta", "0.3", "--f0", "-inf"], "got -inf"),
        (["--excitation", "kanai-tajimi", "--zeta", "0.3", "--f0", "-Infinity"], "got -inf"),
        (["--k3", "-5e5:-1e5:2", "--k", "10"], "k3 = -500000.0 N/m^3"),
    ],
)
def test_negative_infinities_and_sweeps_are_values_not_options(capsys, extra, fragment):
    """`--f0 -inf` is checked as a number, not answered by argparse's "expected one argument"."""
    one_line_error(capsys, [*POWER, *extra], fragment)


def test_sweep_between_huge_ends_is_not_nan(capsys):
    """START:STOP:COUNT near the float limit: the ends themselves are reported, not "nan"."""
    one_line_error(capsys, ["power", "--preset", "coulomb-td1", "--psd=-1e308:1e308:3"],
                   "got -1e+308")  # fmt: skip


def test_band_edge_at_a_subnormal_frequency_is_the_band_from_zero(capsys):
    """`--f-lo 5e-324` integrates like `--f-lo 0` (the bands differ by 5e-324 Hz), instead of
    numpy's "Geometric sequence cannot include zero". Both quadratures are converged far below
    the 1e-9 allowed here (the composite Gauss-Legendre rule of linear_response)."""
    import json

    band = [*POWER, "--excitation", "band-limited", "--f-hi", "20", "--json"]
    results = []
    for f_lo in ("5e-324", "0"):
        code, out, err = run_cli(capsys, *band, "--f-lo", f_lo)
        assert code == 0, err
        results.append(json.loads(out)["velocity_variance"])
    assert results[0] == pytest.approx(results[1], rel=1e-9)


def test_tiny_inductance_under_white_noise_blames_the_inductance(capsys):
    """The refusal names the parameter of extreme magnitude, not "a narrow-band excitation"
    (the input is white)."""
    argv = [*POWER, "--coupling", "inductive", "--alpha", "0.2", "--r-load", "10",
            "--r-coil", "0.48", "--inductance", "1e-300"]  # fmt: skip
    one_line_error(capsys, argv, "inductance = 1e-300 is beyond the range")
    code, out, err = run_cli(capsys, *argv)
    assert "narrow-band" not in err and "array(" not in err, err


def test_predict_broadcasts_over_levels_for_a_piezo_device():
    """`rv.predict(piezo_device, array)` gives each level's scalar prediction (the same fixed
    point, so equal to rounding), not numpy's "only 0-dimensional arrays" error."""
    import numpy as np

    device = rv.Harvester(m=0.0226, c_m=0.049, c_e=0.0, k=57.4, k3=7e4,
                          electrical=rv.Piezo(theta=1e-3, capacitance=1e-8, r_load=1e5))  # fmt: skip
    levels = np.array([0.1, 0.5, 1.0])
    swept = rv.predict(device, levels)
    assert np.shape(swept.power_load) == (3,)
    for i, level in enumerate(levels):
        one = rv.predict(device, float(level))
        assert swept.power_load[i] == pytest.approx(one.power_load, rel=1e-12)
        assert swept.circuit_mean_square[i] == pytest.approx(one.circuit_mean_square, rel=1e-12)
    assert len(swept.to_frame()) == 3


def test_statistic_converts_and_prints_rounded_to_its_interval():
    """float() gives the mean; scaling/shifting by a number maps mean and interval exactly;
    two Statistics do not combine (their correlation is unknown); str rounds to the interval."""
    stat = rv.Statistic(0.0024619412547950926, 0.000272784, 0.000139, 100)
    assert float(stat) == stat.mean
    milli = stat * 1e3
    assert isinstance(milli, rv.Statistic) and milli == 1e3 * stat
    assert milli.mean == pytest.approx(2.4619412547950926, rel=1e-15)
    assert milli.ci95 == pytest.approx(0.272784, rel=1e-15)
    assert (-stat).ci95 == stat.ci95 and (1.0 - stat).mean == pytest.approx(1.0 - stat.mean)
    assert (stat / 4).std_error == pytest.approx(stat.std_error / 4)
    with pytest.raises(TypeError):
        stat * stat
    assert str(stat) == "0.00246 ± 0.00027" == f"{stat}"
    assert f"{stat:.2e}" == "2.46e-03 ± 2.73e-04"


def test_prediction_prints_its_table_with_the_circuit_unit_and_frames_its_sweep():
    """print() gives the table (not the repr), E[V^2] of a piezo in V^2; a broadcast
    to_frame() has a column per swept input so its rows can be told apart."""
    import numpy as np

    piezo = rv.Harvester(m=0.0226, c_m=0.049, c_e=0.0, k=57.4, k3=7e4,
                         electrical=rv.Piezo(theta=1e-3, capacitance=1e-8, r_load=1e5))  # fmt: skip
    text = str(rv.predict(piezo, 1.0))
    assert text.startswith("Prediction (linearisation)") and "PowerPrediction(" not in text
    assert "circuit_mean_square" in text and text.rstrip().endswith("V^2")
    assert "A^2" not in text
    assert "electrical" not in rv.predict(piezo, 1.0).to_dict()

    device = rv.preset("figure9").updated(c_m=np.array([[0.01], [0.02]]))
    frame = rv.predict(device, np.array([1.0, 0.5])).to_frame()
    assert list(frame["psd"]) == [1.0, 0.5, 1.0, 0.5]
    assert list(frame["c_m"]) == [0.01, 0.01, 0.02, 0.02]

    lin = rv.statistical_linearisation(rv.preset("figure9"), rv.BandPass(1.0, 8.0, 0.1))
    assert str(lin).startswith("Statistical linearisation") and "k_eq" in str(lin)


def test_bistable_device_by_its_wells_and_barrier():
    """Harvester.bistable / Potential.from_wells invert z_w = sqrt(-k/k3), Delta U = k^2/(4 k3)
    exactly (to rounding); natural_frequency is the well frequency sqrt(-2k/m), not nan."""
    import numpy as np

    device = rv.Harvester.bistable(0.002, 1e-4, m=0.0226, c_m=0.049, c_e=0.0)
    assert device.k == pytest.approx(-100.0, rel=1e-14)
    assert device.k3 == pytest.approx(2.5e7, rel=1e-14)
    assert device.potential.wells[1] == pytest.approx(0.002, rel=1e-14)
    assert device.potential.barrier_height == pytest.approx(1e-4, rel=1e-14)
    assert device.natural_frequency == pytest.approx(np.sqrt(200.0 / 0.0226), rel=1e-14)
    with pytest.raises(ValueError, match="`barrier`.*> 0 J"):
        rv.Harvester.bistable(0.002, -1.0, m=0.0226, c_m=0.049, c_e=0.0)
    with pytest.raises(ValueError, match="not `k`"):
        rv.Harvester.bistable(0.002, 1e-4, m=0.0226, c_m=0.049, c_e=0.0, k=1.0)


def test_cli_wells_and_barrier_give_the_same_device_and_say_bistable(capsys):
    """`--wells/--barrier` predicts exactly what the equivalent `--k/--k3` predicts, and the
    device line says bistable, where the wells are and the well frequency; a piezo device's
    line has no c_e (it couples through its circuit)."""
    import json

    base = ["power", "--m", "0.0226", "--c-m", "0.049", "--c-e", "0.01", "--psd", "0.005"]
    code, by_wells, err = run_cli(capsys, *base, "--wells", "0.002", "--barrier", "1e-4")
    assert code == 0, err
    assert "bistable: wells at z = +-0.002 m, barrier 0.0001 J, well frequency" in by_wells
    code, by_k, err = run_cli(capsys, *base, "--k=-100", "--k3", "2.5e7", "--json")
    code, by_wells_json, err = run_cli(capsys, *base, "--wells", "0.002", "--barrier", "1e-4",
                                       "--json")  # fmt: skip
    a, b = json.loads(by_k), json.loads(by_wells_json)
    assert a["power_electrical"] == pytest.approx(b["power_electrical"], rel=1e-12)
    one_line_error(capsys, [*base, "--wells", "0.002"], "`--barrier` is missing")
    one_line_error(capsys, [*base, "--wells", "0.002", "--barrier", "1", "--k", "3"], "not both")

    piezo = ["power", "--m", "0.0226", "--c-m", "0.049", "--k", "57.4", "--coupling", "piezo",
             "--theta", "1e-3", "--capacitance", "1e-8", "--r-load", "1e5", "--psd", "1"]  # fmt: skip
    code, out, err = run_cli(capsys, *piezo)
    assert code == 0 and "c_e" not in out.splitlines()[0], out
    assert "circuit_mean_square" in out and "A^2" not in out


def test_power_record_takes_input_column_and_sample_rate_like_identify(capsys, tmp_path):
    """`power --record` reads another column name and a file without time column, and gives
    the same prediction as from the standard file; the options alone are refused."""
    import json

    record = rv.synthetic_record(rv.preset("coulomb-td1"), 2.0, duration=2.0,
                                 sample_rate=1000.0, seed=1)  # fmt: skip
    standard = tmp_path / "standard.csv"
    record.to_csv(standard, float_format=None)
    bare = tmp_path / "bare.csv"
    bare.write_text("acc\n" + "\n".join(repr(float(a)) for a in record["base_acceleration"]))
    argv = ["power", "--preset", "coulomb-td1", "--c-e", "0.01", "--json", "--record"]
    code, out, err = run_cli(capsys, *argv, standard)
    assert code == 0, err
    code, out_bare, err = run_cli(capsys, *argv, bare, "--input-column", "acc",
                                  "--sample-rate", "1000")  # fmt: skip
    assert code == 0, err
    assert json.loads(out_bare)["power_electrical"] == pytest.approx(
        json.loads(out)["power_electrical"],
        rel=1e-9,  # the same samples, the same Welch PSD
    )
    one_line_error(capsys, [*POWER, "--sample-rate", "1000"], "needs `--record`")


def test_validate_accepts_no_progress(capsys, record_csv):
    """`randvib validate --no-progress` is accepted as by every other command."""
    code, out, err = run_cli(capsys, "validate", record_csv[1], record_csv[0], "--no-progress")
    assert code == 0, err
    assert "RMS error (m)" in out  # in the output channel's unit, the relative displacement's


def test_measured_record_names_welch_integral_and_record_variance():
    """A measured excitation reports the integral of its Welch PSD and the samples' variance
    under their own names, not both as "variance"."""
    import numpy as np

    record = rv.synthetic_record(rv.preset("coulomb-td1"), 2.0, duration=2.0,
                                 sample_rate=1000.0, seed=1)  # fmt: skip
    measured = rv.Measured(record)
    parameters = measured.parameters()
    assert "variance" not in parameters
    assert parameters["record_variance"] == pytest.approx(np.var(record["base_acceleration"]))
    assert parameters["psd_integral"] == measured.variance


def test_identification_result_prints_its_table(record_csv):
    """print() of an IdentificationResult is the table of its notebook view, not the repr."""
    fit = rv.identify(rv.read_record(record_csv[0]), "coulomb", m=0.0226, popsize=8, maxiter=2,
                      polish=False, fixed={"k3": 70742.0})  # fmt: skip
    text = str(fit)
    assert text.startswith("Identification") and "IdentificationResult(" not in text
    assert "fc" in text and "N" in text


def test_power_optimal_load_of_a_bridge_on_a_record_runs_on_its_windows(capsys, tmp_path):
    """`power --record R --rectifier bridge --optimal-load --optimal-bounds` searches on the
    record's own windows (not refused), accepts `--no-progress`, prints no empty psd row,
    and its optimum's stored power is Monte Carlo's on those windows at that grid point."""
    import dataclasses
    import json

    record = rv.synthetic_record(rv.preset("coulomb-td1"), 2.0, duration=12.0,
                                 sample_rate=1000.0, seed=3)  # fmt: skip
    path = tmp_path / "rec.csv"
    record.to_csv(path, float_format=None)
    argv = ["power", "--preset", "coulomb-td1", "--coupling", "inductive", "--alpha", "1",
            "--r-coil", "10", "--rectifier", "bridge", "--v-diode", "0.05", "--battery", "1",
            "--record", path, "--optimal-load", "--optimal-bounds", "0", "0.2",
            "--optimal-paths", "4", "--optimal-grid", "3", "--no-progress"]  # fmt: skip
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    assert not any(line.split()[:1] == ["psd"] for line in out.splitlines()), out
    code, out, err = run_cli(capsys, *argv, "--json")
    assert code == 0, err
    best = json.loads(out)
    assert best["optimum_method"] == "monte-carlo" and best["psd"] is None
    harvester = rv.preset("coulomb-td1")
    bridge = rv.BridgeCoil(alpha=1.0, r_coil=10.0, v_diode=0.05, battery=0.1)

    at_grid = rv.monte_carlo_on_record(
        dataclasses.replace(harvester, c_e=0.0, electrical=bridge),
        rv.Measured(rv.read_record(path)), segments=4, burn_in=2.0, progress=False,
    )  # fmt: skip
    # the grid is 0, 0.1, 0.2 V and the best is its middle point (deterministic: the same
    # windows); the search reports Monte Carlo's power at that point on those windows
    assert best["optimum"] == "interior"
    assert best["power_stored_optimal"] == pytest.approx(at_grid.power_stored.mean, rel=1e-12)


def test_probabilities_are_shown_with_unit_one():
    """A stroke exceedance and the events' reached probabilities carry the unit 1, so
    the CLI's unit column is not blank; report headers do not print "(1)"."""
    from randvib.quantities import report_header, unit

    for name in ("stroke_exceedance", "stroke_reached", "stroke_reached_poisson",
                 "stroke_reached_vanmarcke"):  # fmt: skip
        assert unit(name) == "1"
        assert not report_header(name).endswith("(1)")


def test_design_table_gives_every_number_its_unit(capsys):
    """randvib design's table: the varied parameters in their own units (a coupling's
    alpha from its class), probabilities and ratios in 1, powers in W; and the Python
    result's rows and print() (randvib.harvester_design.result) the same."""
    code, out, err = run_cli(
        capsys, "design", "--preset", "coulomb-td1", "--psd", "0.5", "--stroke", "0.01",
        "--alpha", "0.2", "--r-load", "1", "--r-coil", "0.48", "--vary", "k=20:200",
        "--vary", "alpha=0.05:0.5", "--exceedance", "0.01", "--no-monte-carlo",
        "--no-progress",
    )  # fmt: skip
    assert code == 0, err
    units = {}
    for line in out.splitlines():
        for name in ("optimum k", "optimum alpha", "power_predicted",
                     "stroke_exceedance_predicted", "input_power", "efficiency"):  # fmt: skip
            if line.startswith(name + " "):
                units[name] = line.split()[-1]
    assert units == {
        "optimum k": "N/m", "optimum alpha": "Wb/m", "power_predicted": "W",
        "stroke_exceedance_predicted": "1", "input_power": "W", "efficiency": "1",
    }  # fmt: skip
    h = rv.Harvester.from_electrical(
        m=0.0226, c_m=0.049, k=57.4, alpha=0.2, r_load=1.0, r_coil=0.48, k3=7e4, stroke=0.01
    )
    result = rv.design(h, 0.5, {"alpha": (0.05, 0.5)}, exceedance=0.01, monte_carlo=False)
    rows = {name: u for name, _, u in result._rows()}
    assert rows["alpha"] == "Wb/m" and rows["power_predicted"] == "W"
    assert rows["stroke_exceedance_predicted"] == "1"
    # print(result) shows the table, as print() of the other results does, not the repr
    assert str(result).startswith("Design") and "DesignResult(" not in str(result)


@pytest.mark.parametrize("output", [{"battery": 0.03}, {"storage_capacitance": 1.0, "r_load": 2.5}])
def test_dc_optimum_bound_is_offered_and_a_refusal_shows_the_ratio_above_the_limit(output):
    """optimal_dc_output's upper bound (randvib.analytic.bridge) is a value the closure
    takes: predict at it answers (brentq's root could land a hair beyond the limit, and
    an optimum there was refused); just beyond it the refusal prints the ratio with the
    digits that show it above 1.25, not "1.25 (limit 1.25)"; print() of the optimum
    gives its units."""
    import dataclasses

    base = rv.preset("figure9")

    def wired(coil):
        return rv.Harvester.with_coupling(base.m, base.c_m, base.k, coil, k3=base.k3,
                                          friction=base.friction)  # fmt: skip

    coil = rv.BridgeCoil(0.1992, 0.48, v_diode=0.01, **output)
    best = rv.optimal_dc_output(wired(coil), 1.0)
    # print(best) is one line with units, not the dataclass' repr
    unit = "V" if best.parameter == "battery" else "ohm"
    assert str(best).startswith(f"{best.parameter} = ") and f" {unit} (" in str(best)
    at_bound = dataclasses.replace(coil, **{best.parameter: best.upper})
    assert rv.predict(wired(at_bound), 1.0, "bridge-closure").power_stored > 0
    beyond = dataclasses.replace(coil, **{best.parameter: best.upper * (1 + 1e-6)})
    with pytest.raises(ValueError, match="bridge-closure") as info:
        rv.predict(wired(beyond), 1.0, "bridge-closure")
    shown = float(str(info.value).split("threshold is ")[1].split()[0])
    assert shown > 1.25, str(info.value)


def test_rectifier_without_a_coupling_says_none_given(capsys):
    """`--rectifier bridge` without --coupling (randvib.cli._device): the refusal says none
    was given instead of printing Python's None."""
    one_line_error(capsys, ["power", "--preset", "figure9", "--rectifier", "bridge", "--psd", "1"],
                   "`--coupling inductive|piezo`; none given")  # fmt: skip
    _, _, err = run_cli(capsys, "power", "--preset", "figure9", "--rectifier", "bridge")
    assert "None" not in err


def test_json_of_power_simulate_and_design_carries_units(capsys):
    """--json of power, simulate and design (randvib.cli._output.with_units) has a units
    entry as identify's has: the circuit's mean square in the piezo's V^2, a probability 1."""
    piezo = ["--preset", "figure9", "--coupling", "piezo", "--theta", "1e-4",
             "--capacitance", "1e-9", "--r-load", "1e6", "--psd", "0.5", "--stroke", "0.01"]  # fmt: skip
    import json

    code, out, err = run_cli(capsys, "power", *piezo, "--json")
    assert code == 0, err
    units = json.loads(out)["units"]
    assert units["circuit_mean_square"] == "V^2" and units["stroke_exceedance"] == "1"
    assert units["power_electrical"] == "W" and "method" not in units
    code, out, err = run_cli(capsys, "simulate", "--preset", "coulomb-td1", "--psd", "0.5",
                             "--stroke", "0.01", "--paths", "4", "--t-end", "3", "--json")  # fmt: skip
    assert code == 0, err
    units = json.loads(out)["units"]
    assert units["velocity_variance"] == "(m/s)^2" and units["stroke_exceedance"] == "1"
    code, out, err = run_cli(capsys, "design", "--preset", "coulomb-td1", "--c-e", "0.05",
                             "--psd", "0.5", "--stroke", "0.01", "--vary", "k=20:200",
                             "--no-monte-carlo", "--no-progress", "--json")  # fmt: skip
    assert code == 0, err
    units = json.loads(out)["units"]
    assert units["k"] == "N/m" and units["efficiency"] == "1" and units["input_power"] == "W"


def test_design_of_a_device_that_harvests_nothing_is_refused_not_an_internal_error(capsys):
    """A preset identified without the coil (c_e = 0) whose --vary chooses only k: the
    search (randvib.harvester_design.search) has nothing to maximise; one line says so
    instead of an internal ZeroDivisionError."""
    one_line_error(capsys, ["design", "--preset", "coulomb-td1", "--psd", "0.5", "--stroke",
                            "0.01", "--vary", "k=20:200", "--no-monte-carlo", "--no-progress"],
                   "power is 0 at every feasible point")  # fmt: skip


# ------------------------------------------------------- issue 35: first-hour trips
BRIDGE_CLI = ["--preset", "figure9", "--psd", "1", "--coupling", "inductive", "--rectifier", "bridge", "--alpha", "0.1992",
              "--r-coil", "0.48", "--v-diode", "0.01", "--battery", "0.02"]  # fmt: skip


def _bridge_device(battery=0.02, k3=None, v_diode=0.01):
    base = rv.preset("figure9")
    coil = rv.BridgeCoil(0.1992, 0.48, v_diode=v_diode, battery=battery)
    return rv.Harvester.with_coupling(base.m, base.c_m, base.k, coupling=coil,
                                      k3=base.k3 if k3 is None else k3, friction=base.friction)  # fmt: skip


def test_predict_of_a_bridge_uses_the_method_randvib_power_uses(capsys):
    """rv.predict(bridge, 1.0) refused with the linearisation message while `randvib power`
    answered with the bridge closure: the API's default is now the command's."""
    import json

    device = _bridge_device()
    default = rv.predict(device, 1.0)
    assert default.method == "bridge-closure"
    assert default.power_stored == rv.predict(device, 1.0, "bridge-closure").power_stored
    assert rv.expected_power(device, 1.0) == default.power_electrical
    code, out, err = run_cli(capsys, "power", *BRIDGE_CLI, "--json")
    assert code == 0, err
    assert json.loads(out)["power_stored"] == pytest.approx(default.power_stored, rel=1e-12)
    # a device without a bridge keeps statistical linearisation
    assert rv.predict(rv.preset("figure9"), 1.0).method == "linearisation"


def test_optimal_dc_output_refusal_names_the_monte_carlo_optimum():
    """The refusal pointed to rv.simulate, which gives no optimum: it names
    rv.simulated_dc_optimum, the search that does."""
    band = rv.BandPass(level=1.0, f0=8.0, zeta=0.1)
    with pytest.raises(ValueError, match=r"randvib\.simulated_dc_optimum") as info:
        rv.optimal_dc_output(_bridge_device(k3=1e7), band)
    assert "randvib.simulate)" not in str(info.value)
    # beyond the closure's validity at every battery voltage (0.3 V drops, white noise)
    with pytest.raises(ValueError, match=r"no battery within .*randvib\.simulated_dc_optimum"):
        rv.optimal_dc_output(_bridge_device(v_diode=0.3), 1.0)


def test_help_is_plain_text_and_the_namespace_holds_only_randvib(capsys):
    """`randvib --help` showed ``randvib <command> ...`` (reStructuredText); `rv.importlib`
    was public (the lazy loader's own import)."""
    from randvib.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args(["--help"])
    out = capsys.readouterr().out
    assert "``" not in out and "randvib <command> [options]" in out
    assert "importlib" not in dir(rv) and not hasattr(rv, "importlib")


def test_device_line_names_shockley_parameters_only_for_shockley_diodes(capsys):
    """A constant drop (--v-diode) has no ideality or thermal voltage to show."""
    code, out, err = run_cli(capsys, "power", *BRIDGE_CLI)
    assert code == 0, err
    device_line = out.splitlines()[0]
    assert "v_diode 0.01 V" in device_line
    assert "ideality" not in device_line and "thermal_voltage" not in device_line
    shockley = rv.BridgeCoil(0.1992, 0.48, battery=0.02, saturation_current=1e-9)
    assert {"ideality", "thermal_voltage", "saturation_current"} <= set(shockley.parameters())
    assert "ideality" not in rv.BridgeCoil(0.1992, 0.48, v_diode=0.01, battery=0.02).parameters()


def test_every_gallery_script_shows_its_figures_when_run_as_a_script():
    """Run with `python examples/plot_NN.py`, a gallery script drew figures and ended
    without showing them (the gallery draws them itself): each ends with plt.show()."""
    import ast
    from pathlib import Path

    scripts = sorted((Path(__file__).parents[1] / "examples").glob("plot_*.py"))
    assert scripts
    for script in scripts:
        last = ast.parse(script.read_text()).body[-1]
        assert ast.unparse(last) == "plt.show()", script.name
