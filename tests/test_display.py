"""Results in notebooks and pandas: compact reprs, HTML tables, to_frame/to_dict.

Covers :mod:`randvib._display` (plain-text and HTML tables, pandas) through the result
types (:mod:`randvib.montecarlo.results`, :mod:`randvib.analytic.power_prediction`,
:mod:`randvib.analytic.statistical_linearisation`,
:mod:`randvib.identification.result`), the digits they show (:mod:`randvib.formatting`)
and their units (:mod:`randvib.quantities`).
"""

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
    assert not frame.loc["m", "free"] and np.isnan(frame.loc["m", "lower"])
    assert frame.loc["fc", "upper"] == 0.02
    assert "(fixed)" in result._repr_html_()


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
