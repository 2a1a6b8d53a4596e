"""Results in notebooks and pandas: compact reprs, HTML tables, to_frame/to_dict.

Covers :mod:`randvib._display` (plain-text and HTML tables, pandas) through the result
types (:mod:`randvib.montecarlo.results`, :mod:`randvib.analytic.power_prediction`,
:mod:`randvib.analytic.statistical_linearisation`,
:mod:`randvib.identification.result`), the digits they show (:mod:`randvib.formatting`)
and their units (:mod:`randvib.quantities`).
"""

import re

import numpy as np
import pytest

import randvib as rv
from randvib import formatting
from randvib.identification.result import IdentificationResult


@pytest.fixture(scope="module")
def simulation():
    return rv.simulate(
        rv.preset("figure9"),
        1.0,
        t_end=1.0,
        burn_in=0.2,
        dt=5e-4,
        n_paths=32,
        seed=4,
        progress=False,
    )


def test_estimate_shows_the_digits_its_interval_supports():
    # one notation for the pair, chosen by the mean (as in the CLI's tables)
    assert formatting.estimate(0.0024646123, 5.4568e-7) == "0.00246461 ± 0.00000055"
    assert formatting.estimate(9.2912e-06, 9.81e-07) == "9.29e-06 ± 9.8e-07"
    assert formatting.estimate(12.3456, 0.25) == "12.35 ± 0.25"
    assert formatting.estimate(0.001346, 0.000295) == "0.00135 ± 0.00030"  # zeros kept
    assert formatting.estimate(134.55, 29.5) == "135 ± 30"
    assert formatting.estimate(1e-3, 0.0) == "0.001"  # no interval: six figures at most


def test_simulation_frame_holds_the_statistics(simulation):
    frame = simulation.to_frame()
    for name in ("power_electrical", "velocity_variance", "friction_power"):
        stat = getattr(simulation, name)
        assert frame.loc[name, "mean"] == stat.mean
        assert frame.loc[name, "ci95"] == stat.ci95
        assert frame.loc[name, "n_paths"] == 32
    assert frame.loc["power_electrical", "unit"] == "W"
    assert "power_load" not in frame.index  # no circuit, no row
    assert simulation.to_dict() == simulation.summary()


def test_simulation_repr_is_one_compact_line(simulation):
    text = repr(simulation)
    assert "\n" not in text and len(text) < 250
    assert "32 paths" in text and "power_electrical" in text
    html = simulation._repr_html_()
    assert html.startswith("<table>") and html.count("<tr>") == 1 + len(simulation.to_frame())
    assert "friction_power" in str(simulation)


def test_broadcast_prediction_flattens_to_one_row_per_point():
    fc = np.linspace(0.0, 0.02, 3)
    psd = np.array([[1.0], [0.5]])
    prediction = rv.predict(rv.preset("figure9").updated(fc=fc), psd)
    frame = prediction.to_frame()
    assert len(frame) == 6
    np.testing.assert_array_equal(frame["power_electrical"], prediction.power_electrical.ravel())
    # row i is the point unravel_index(i, shape): here (1, 2), S = 0.5 and Fc = 0.02
    single = rv.expected_power(rv.preset("figure9").updated(fc=0.02), 0.5)
    assert frame["power_electrical"][5] == pytest.approx(single, rel=1e-12)
    assert "array(2, 3)" in repr(prediction) and "\n" not in repr(prediction)


def test_linearisation_frame_is_its_dict():
    result = rv.statistical_linearisation(rv.preset("figure9"), rv.BandPass(1.0, 8.0, 0.1))
    row = result.to_frame().iloc[0]
    assert row["power_electrical"] == result.power_electrical
    assert row["excitation"] == "band-pass" and row["excitation_f0"] == 8.0
    assert "BandPass" in repr(result) and "harvester" not in repr(result)
    assert "k_eq" in result._repr_html_()


def test_identification_repr_leaves_the_history_out():
    history = {"best": list(np.linspace(1.0, 0.01, 500)), "nfev": list(range(500))}
    result = IdentificationResult(
        model="coulomb",
        parameters={"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 7.07e4, "fc": 0.0058},
        free=("c", "k", "k3", "fc"),
        cost=0.0079,
        bounds={"c": (1e-4, 1.0), "k": (5.0, 500.0), "k3": (0.0, 1e7), "fc": (0.0, 0.02)},
        nfev=20000,
        generations=500,
        elapsed=12.0,
        simulations_per_second=1.7e3,
        message="converged",
        history=history,
    )
    text = repr(result)
    assert len(text) < 200 and "0.0079" in text and "fc=0.0058" in text
    frame = result.to_frame()
    assert frame.loc["k", "value"] == 57.4 and frame.loc["k", "unit"] == "N/m"
    assert not frame.loc["m", "free"] and np.isnan(frame.loc["m", "search_lower"])
    assert frame.loc["fc", "search_upper"] == 0.02  # the search box, named as such
    assert "lower" not in frame.columns and "upper" not in frame.columns
    assert np.isnan(frame.loc["k", "std_error"])  # no polish: no standard error, no interval
    assert "(fixed)" in result._repr_html_() and "polish was skipped" in str(result)


def _fitted(**changes):
    """A saved fit with standard errors and residual diagnostics (as identify writes them)."""
    names = ["c", "k", "k3", "fc"]
    saved = {
        "model": "coulomb",
        "parameters": {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 7.07e4, "fc": 0.0058},
        "free": names,
        "cost": 0.0079,
        "bounds": {"c": [1e-4, 1.0], "k": [5.0, 500.0], "k3": [0.0, 1e7], "fc": [0.0, 0.02]},
        "record": "test",
        "simulations": 2000,
        "generations": 50,
        "elapsed_s": 3.0,
        "simulations_per_second": 700.0,
        "message": "converged",
        "settings": {},
        "standard_errors": {"c": 0.002, "k": 0.3, "k3": 900.0, "fc": 0.0004},
        "correlation": {"names": names, "matrix": np.eye(4).tolist()},
        "noise_std": 1e-6,
        "dof": 996,
        "residuals": {
            "verdict": "structured",
            "level": 0.01,
            "ljung_box": 80.0,
            "ljung_box_p": 1e-7,
            "cross_correlation_p": 0.5,
            "autocorrelation_band": 0.08,
            "cross_correlation_band": 0.08,
            "autocorrelation": [1.0, 0.3, 0.1],
            "cross_correlation": [0.0, 0.01, 0.0, 0.02, 0.0],
            "max_lag": 2,
            "samples": 1000,
        },  # fmt: skip
    }
    saved.update(changes)
    return IdentificationResult.from_dict(saved)


def test_identification_frame_and_print_show_the_standard_errors_and_the_verdict():
    """A notebook user reads intervals in to_frame() and print(): the 95 % interval is
    value +- t(0.975, dof) SE, the search box is named search_lower/search_upper, and the
    residual verdict is in the table, the repr and the frame's source dict."""
    from scipy import stats

    result = _fitted()
    frame = result.to_frame()
    t = stats.t.ppf(0.975, 996)
    assert frame.loc["k", "std_error"] == 0.3
    assert frame.loc["k", "ci95_lower"] == pytest.approx(57.4 - t * 0.3, rel=1e-12)
    assert frame.loc["k", "ci95_upper"] == pytest.approx(57.4 + t * 0.3, rel=1e-12)
    assert (frame.loc["k", "search_lower"], frame.loc["k", "search_upper"]) == (5.0, 500.0)
    assert frame.loc["k", "status"] == "identified" and frame.loc["m", "status"] == "fixed"
    assert np.isnan(frame.loc["m", "std_error"]) and np.isnan(frame.loc["m", "ci95_lower"])
    text = str(result)
    assert "57.40 ± 0.30 [56.81, 57.99]" in text, text
    assert re.search(r"\n  residual\s+structured\n", text), text
    assert "k=57.40 ± 0.30" in repr(result) and "residual structured" in repr(result)
    # a parameter the search left on its bound: no interval, its status says so
    on_bound = _fitted(parameters={"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 0.0, "fc": 0.0058})
    row = on_bound.to_frame().loc["k3"]
    assert row["status"] == "at lower bound" and np.isnan(row["ci95_lower"])
    assert "k3 (at lower bound)" in str(on_bound)


def test_record_and_prediction_reprs_name_what_they_hold():
    """Record's repr names its channels, and each is an attribute by that name; a
    prediction, a batch response and residual diagnostics print their sizes and scores,
    not arrays; a batch of one device makes a Record."""
    record = rv.synthetic_record(
        rv.preset("coulomb-td1"), 2.0, duration=0.1, sample_rate=1000.0, seed=2
    )
    assert "relative_displacement" in repr(record)
    assert record.relative_displacement is record.z
    assert record.base_acceleration is record.input
    with pytest.raises(AttributeError, match="no 'force' channel; it has base_acceleration"):
        _ = record.force
    assert not hasattr(record, "base_velocity")
    device = rv.preset("coulomb-td1")
    batch = rv.record_response(device, record)
    assert batch.z.shape == (1, 100) and "array" not in repr(batch) and "1 device" in repr(batch)
    rebuilt = batch.to_record()
    np.testing.assert_array_equal(rebuilt.z, batch.z[0])
    np.testing.assert_array_equal(rebuilt.base_acceleration, record.base_acceleration)
    with pytest.raises(ValueError, match=r"one row of a batch"):
        rv.Record(record.dt, relative_displacement=batch.z, base_acceleration=record.input)
    two = rv.record_response(device.updated(fc=np.array([0.0, 0.0058])), record)
    with pytest.raises(ValueError, match="2 devices: give `index`"):
        two.to_record()
    np.testing.assert_array_equal(two.to_record(1).z, two.z[1])
    prediction = rv.predict_record(device, record)
    text = repr(prediction)
    assert "array" not in text and "J = " in text and "'synthetic'" in text and "\n" not in text
    diagnostics = _fitted().residuals
    assert repr(diagnostics).startswith("ResidualDiagnostics(residual structured")
    assert "array" not in repr(diagnostics)


def test_results_under_a_table_or_a_record_show_themselves():
    """psd is None there (no single level): repr, str and HTML name the input instead."""
    table = rv.Tabulated(np.array([1.0, 5.0, 20.0, 30.0]), np.array([0.0, 1.0, 1.0, 0.0]))
    device = rv.preset("figure9")
    result = rv.simulate(device, table, t_end=0.3, burn_in=0.1, dt=1e-3, n_paths=4, progress=False)
    assert result.psd is None
    for text in (repr(result), str(result), result._repr_html_()):
        assert "tabulated" in text and "S = " not in text
    record = rv.Measured(
        rv.Record(time=np.arange(4000) * 1e-3, base_acceleration=table.sample(4.0, 1e-3, seed=1)[0])
    )
    on_record = rv.monte_carlo_on_record(device, record, segments=2, burn_in=0.5, progress=False)
    assert on_record.psd is None
    assert repr(on_record).startswith("RecordSimulation(") and "measured" in repr(on_record)
    assert "array" not in repr(on_record)  # not the record's samples


def test_tables_records_and_spectra_have_compact_reprs(simulation):
    """Objects holding long arrays show their size and range, never the arrays."""
    table = rv.Tabulated(np.array([1.0, 5.0, 20.0, 30.0]), np.array([0.0, 1.0, 1.0, 0.0]))
    # variance: the trapezoid's exact integral, 2 + 15 + 5 = 22 (m/s^2)^2
    assert repr(table) == "Tabulated(4 points, 1-30 Hz, variance 22 (m/s^2)^2)"
    record = rv.Measured(
        rv.Record(
            time=np.arange(4000) * 1e-3,
            base_acceleration=np.random.default_rng(0).normal(size=4000),
        )
    )
    assert repr(record).startswith("Measured(4000 samples at 1000 Hz, 4 s, Welch PSD integral ")
    statistical = rv.statistical_linearisation(rv.preset("figure9"), table)
    assert "array" not in repr(statistical) and "array" not in statistical._repr_html_()
    spectra = rv.simulate(
        rv.preset("figure9"),
        1.0,
        t_end=1.0,
        burn_in=0.1,
        dt=1e-3,
        n_paths=2,
        record_paths=2,
        progress=False,
    ).response_spectra()
    text = repr(spectra)
    assert text.startswith(
        f"SampledSpectra({spectra.frequency.size} frequencies, 0-500 Hz, 2 paths"
    )
    assert len(text) < 200


def test_units_come_from_one_vocabulary():
    """Result types take a quantity's unit from randvib.quantities: a circuit state's
    mean square in its coupling's unit squared, and one unit per name everywhere."""
    from randvib.quantities import unit

    piezo = rv.Harvester.with_coupling(
        0.0226, 0.05, 57.4, rv.Piezo(theta=2e-3, capacitance=1e-7, r_load=1e5)
    )
    coil = rv.Inductive(alpha=0.1992, r_load=0.5, r_coil=0.48, inductance=2e-3)
    assert unit("circuit_mean_square", coil) == "A^2"
    assert unit("circuit_variance", piezo.electrical) == "V^2"
    assert unit("circuit_mean_square") == "A^2 or V^2"  # the device unknown (a PowerPrediction)
    lin = rv.statistical_linearisation(piezo, rv.BandPass(1.0, 8.0, 0.2))
    assert {name: u for name, _, u in lin._rows()}["circuit_variance"] == "V^2"
    prediction = rv.predict(rv.preset("figure9"), 1.0)
    assert all(u == unit(name) for name, _, u in prediction._quantities())
    with pytest.raises(KeyError, match="not a reported quantity"):
        unit("power")


def test_simulation_result_round_trips_through_json(simulation):
    """SimulationResult had no from_dict (reload only by pickle): to_dict(per_path=True)
    and from_dict give back every statistic exactly, through JSON text, the device (with
    its friction and stroke) and a named excitation rebuilt; a summary alone, or a table
    excitation without the table, is refused with what to do."""
    import json

    from randvib._io import dumps

    back = rv.SimulationResult.from_dict(json.loads(dumps(simulation.to_dict(per_path=True))))
    assert back.summary() == simulation.summary()
    assert back.harvester.parameters() == simulation.harvester.parameters()
    banded = rv.simulate(rv.preset("figure9").updated(stroke=0.002), rv.BandPass(1.0, 8.0, 0.2),
                         t_end=0.3, burn_in=0.1, dt=5e-4, n_paths=4, seed=1, progress=False)  # fmt: skip
    again = rv.SimulationResult.from_dict(json.loads(dumps(banded.to_dict(per_path=True))))
    assert again.summary() == banded.summary() and again.excitation.f0 == 8.0
    with pytest.raises(ValueError, match=r"to_dict\(per_path=True\)"):
        rv.SimulationResult.from_dict(simulation.to_dict())
    table = rv.Tabulated(np.array([1.0, 5.0, 20.0, 30.0]), np.array([0.0, 1.0, 1.0, 0.0]))
    tabled = rv.simulate(rv.preset("figure9"), table, t_end=0.3, burn_in=0.1, dt=1e-3,
                         n_paths=4, progress=False)  # fmt: skip
    saved = json.loads(dumps(tabled.to_dict(per_path=True)))
    with pytest.raises(ValueError, match="pass it as `excitation`"):
        rv.SimulationResult.from_dict(saved)
    assert rv.SimulationResult.from_dict(saved, excitation=table).summary() == tabled.summary()
