"""What the studies' figures show, read from the Axes they draw (a reviewer's checks).

No point is silently dropped from a logarithmic axis, levels and lines are
named in the legend, the natural frequency is typeset, a symmetric-log axis
carries ticks a reader can place -40 % by, a second axis over a logarithmic
one is logarithmic too, and the limits follow the data rather than a legend.

Covers :mod:`randvib.studies.figures` (power against stroke exceedance, method
errors against the level), :mod:`randvib.studies.spectra_figure`, the events'
figure (:mod:`randvib.studies.transient_figure`) and the dc-power study's figure
(:mod:`randvib.study_scripts.dc_power`).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

import randvib as rv  # noqa: E402
from randvib.studies import figures  # noqa: E402

DEVICES = ("linear", "bistable")
LEVELS = (1 / 16, 1 / 4, 1.0)


@pytest.fixture
def drawn(monkeypatch):
    """The figures the functions would save, kept open for inspection."""
    kept = []

    def keep(fig, path, **_):
        kept.append(fig)
        return path

    monkeypatch.setattr(figures, "save_figure", keep)
    yield kept
    plt.close("all")


def exceedance_table() -> pd.DataFrame:
    rows = []
    for name in ("white", "band at f_n"):
        for d, dev in enumerate(DEVICES):
            for i, g in enumerate(LEVELS):
                # the linear device never passes the stroke at the lowest level
                exceedance = 0.0 if (dev == "linear" and i == 0) else 10.0 ** (i - 4 + d)
                rows.append({"input": name, "device": dev, "g": g,
                             "power_mc": 1e-3 * g, "power_mc_ci95": 1e-5 * g,
                             "exceedance_mc": exceedance,
                             "exceedance_mc_ci95": 0.1 * exceedance})  # fmt: skip
    return pd.DataFrame(rows)


def marker_points(ax):
    """(x, y) of every drawn data marker (the joining lines and the caps left out)."""
    points = []
    for line in ax.get_lines():
        caps = ("|", "_", None, "None", "")  # error-bar caps are markers too
        if line.get_marker() not in caps:
            points += list(zip(line.get_xdata(), line.get_ydata(), strict=True))
    return points


def test_zero_exceedance_is_marked_at_the_edge_not_dropped(drawn, tmp_path):
    table = exceedance_table()
    figures.power_against_exceedance(table, DEVICES, 0.01, 0.012, tmp_path / "x.png")
    (fig,) = drawn
    axes = [ax for ax in fig.axes if ax.get_xscale() == "log"]
    assert len(axes) == 2
    smallest = table.exceedance_mc[table.exceedance_mc > 0].min()
    for ax in axes:
        points = marker_points(ax)
        assert len(points) == len(DEVICES) * len(LEVELS)  # every level of every device
        left = min(x for x, _ in points)
        assert 0 < left < smallest and ax.get_xlim()[0] < left  # inside the axis, left of all
        assert ax.get_xlim()[0] > 0.01 * smallest  # the axis shows data, not decades of room
    assert axes[1].get_title() == "band at $f_n$"


def test_hollow_edge_markers_of_two_devices_with_equal_power_do_not_coincide(drawn, tmp_path):
    """Two devices that never pass the stroke at a level with the same power: their
    hollow edge markers are staggered, not one drawn over the other."""
    table = exceedance_table()
    table.loc[table.g == LEVELS[0], "exceedance_mc"] = 0.0  # both devices, same power_mc
    figures.power_against_exceedance(table, DEVICES, 0.01, 0.012, tmp_path / "x.png")
    (fig,) = drawn
    for ax in [ax for ax in fig.axes if ax.get_xscale() == "log"]:
        low = [(x, y) for x, y in marker_points(ax) if y == pytest.approx(LEVELS[0])]  # mW
        assert len(low) == 2 and low[0][0] != pytest.approx(low[1][0], rel=0.2)
        assert all(ax.get_xlim()[0] < x for x, _ in low)


def test_exceedance_legend_names_devices_levels_and_the_hollow_marker(drawn, tmp_path):
    figures.power_against_exceedance(exceedance_table(), DEVICES, 0.01, 0.012, tmp_path / "x.png")
    (fig,) = drawn
    (legend,) = fig.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert {"linear", "bistable", "g = 1/16", "g = 1/4", "g = 1"} <= set(texts)
    assert any("never beyond" in t for t in texts) and any("budget" in t for t in texts)
    assert "lines" in legend.get_title().get_text() and "markers" in legend.get_title().get_text()


def test_symlog_error_axis_has_ticks_to_read_minus_forty_percent(drawn, tmp_path):
    rows = []
    for dev in DEVICES:
        for g in LEVELS:
            for method, err in (("linearisation", -0.45 * g), ("fpk-fast", 0.02 * g)):
                rows.append({"method": method, "device": dev, "g": g,
                             "power_rel_error": err, "power_rel_error_ci95": 0.01,
                             "exceedance_rel_error": err / 2,
                             "exceedance_rel_error_ci95": 0.02})  # fmt: skip
    figures.method_errors_against_level(pd.DataFrame(rows), DEVICES, tmp_path / "m.png")
    (fig,) = drawn
    power_axis = fig.axes[0]
    assert power_axis.get_yscale() == "symlog"
    ticks = set(np.round(power_axis.get_yticks(), 6))
    assert {-40.0, -20.0, -10.0, 0.0} <= ticks
    labels = [t.get_text() for t in power_axis.get_yticklabels()]
    assert "-40" in [label.replace("\u2212", "-") for label in labels]


def test_spectra_limits_follow_the_lines_and_the_excitation_axis_is_logarithmic():
    f = np.linspace(0.0, 200.0, 2001)
    device = rv.preset("figure9")
    spectra = rv.statistical_linearisation(device, rv.BandPass(1.0, 8.0, 0.1)).response_spectra(f)
    fig = rv.plot_response_spectra({"lin.": spectra}, excitation=rv.BandPass(1.0, 8.0, 0.1))
    try:
        f_max = fig.axes[0].get_xlim()[1]
        shown = (f > 0) & (f <= f_max)
        for ax, name in zip(fig.axes[:3], ("displacement", "velocity", "power"), strict=True):
            values = np.asarray(getattr(spectra, name))[shown]
            assert ax.get_ylim() == pytest.approx((0.5 * values.min(), 2.0 * values.max()))
        twins = [ax for ax in fig.axes[3:] if ax.get_ylabel()]
        assert len(twins) == 1 and twins[0].get_yscale() == "log"
        (legend,) = fig.legends
        assert "base excitation (right axis)" in [t.get_text() for t in legend.get_texts()]
    finally:
        plt.close(fig)


def test_dc_power_series_that_stores_nothing_is_drawn_hollow_at_a_floor(monkeypatch, tmp_path):
    """The dc-power figure: a diode drop at which the bridge never conducts (0 W) is drawn
    as hollow markers at a floor below every stored power, named in the legend, not lost
    from the log axis; covers the figure of ``randvib.study_scripts.dc_power``."""
    from randvib.study_scripts import dc_power

    kept = []
    monkeypatch.setattr(dc_power, "save_figure", lambda fig, path, **_: kept.append(fig))
    rows = [{"psd": s, "v_diode": v_d, "battery": 0.03, "power_stored": p,
             "power_stored_ci95": 0.05 * p, "power_resistive": 2e-4 * s}
            for s in (0.25, 1.0) for v_d, p in ((0.0, 1e-4 * s), (0.3, 0.0))]  # fmt: skip
    dc_power.figure(pd.DataFrame(rows), tmp_path)
    (ax,) = kept[0].axes
    hollow = [line for line in ax.get_lines() if line.get_markerfacecolor() == "white"]
    assert len(hollow) == 1 and len(hollow[0].get_xdata()) == 2  # both levels of V_d = 0.3 V
    assert 0 < max(hollow[0].get_ydata()) < 1e-4 * 0.25
    (legend,) = kept[0].legends  # beside the axes, off the data (issue 35, item 17)
    assert ax.get_legend() is None
    texts = [t.get_text() for t in legend.get_texts()]
    assert any("0.3 V" in t and "0 W" in t for t in texts)
    assert not any("0.3 V, best" in t for t in texts)  # no entry for an empty series
    plt.close("all")


@pytest.fixture(scope="module")
def event_results():
    """A linear device with a stroke through a short event: Monte Carlo and the exact curves."""
    device = rv.preset("figure9").updated(fc=0.0, k3=0.0, stroke=0.003)
    event = rv.Enveloped(rv.BandPass(2.0, 8.0, 0.2), rv.ShinozukaSato.unit_peak(0.5, 2.0))
    times = np.linspace(0.0, 2.0, 11)
    simulated = rv.simulate_transient(device, event, t_end=2.0, dt=5e-4, n_paths=40,
                                      times=times, seed=3, progress=False)  # fmt: skip
    exact = rv.transient_response(device, event, np.linspace(0.0, 2.0, 201))
    return simulated, exact


def test_transient_figure_shows_energy_and_the_stroke_and_keeps_its_legend_off_the_data(
    event_results,
):
    """Panels b and c were one curve scaled by c_e (issue 35, item 10): the figure now shows
    the energy harvested since t = 0 (Monte Carlo's whole event at its end) and P(stroke
    reached) with its Wilson interval beside the labelled approximations; one legend below
    the panels; the envelope's axis starts at the data axis' zero."""
    simulated, exact = event_results
    fig = rv.plot_transient({"linear": (simulated, exact)})
    axes = [ax for ax in fig.axes if ax.get_ylabel() != "$e(t)^2$"]
    labels = [ax.get_ylabel() for ax in axes]
    assert labels == ["E[$z^2$] (mm$^2$)", "E[$P_e$] (mW)", "energy since t = 0 (mJ)",
                      "P(|z| reached the stroke)"]  # fmt: skip
    energy_ax, stroke_ax = axes[2], axes[3]
    curve = next(line for line in energy_ax.get_lines() if len(line.get_xdata()) > 100)
    assert curve.get_ydata()[-1] == pytest.approx(1e3 * exact.energy_electrical, rel=1e-9)
    marker = next(line for line in energy_ax.get_lines() if list(line.get_xdata()) == [2.0])
    assert marker.get_ydata()[0] == pytest.approx(1e3 * simulated.energy_electrical.mean)
    reached = simulated.stroke_reached
    assert np.all(reached.lower >= 0.0) and np.all(reached.upper <= 1.0)
    stroke_labels = [line.get_label() for line in stroke_ax.get_lines()]
    assert "linear (Poisson, approximate)" in stroke_labels
    assert "linear (Vanmarcke, approximate)" in stroke_labels
    (bound,) = [line for line in stroke_ax.get_lines() if "upper bound" in line.get_label()]
    np.testing.assert_array_equal(bound.get_ydata(), exact.stroke_reached_bound)
    assert all(ax.get_legend() is None for ax in fig.axes) and len(fig.legends) == 1
    twin = next(ax for ax in fig.axes if ax.get_ylabel() == "$e(t)^2$")
    assert twin.get_ylim()[0] == 0.0 == axes[0].get_ylim()[0]
    plt.close(fig)
