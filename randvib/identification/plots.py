"""Figures for identification results (paper Figures 7 and 8).

Numbers come from :mod:`randvib.identification.prediction` (``Prediction`` objects and
cost tables); these functions only draw them, in the shared style of
:mod:`randvib.figure_style` (constrained layout, panel letters, the Okabe-Ito
palette, units in mathtext). Each returns the figure; given ``path`` it also
writes the PNG (after the layout check) and closes it.
"""

from __future__ import annotations

import numpy as np

from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled

#: Colour, marker and label of each friction model. Coulomb and tanh fits are
#: often equal to plotting accuracy: Coulomb is drawn as a larger open marker
#: under tanh's small filled one, so both stay visible.
MODEL_STYLE = {
    "viscous": dict(color="#555555", marker="s", ms=4, label="no friction (viscous)"),
    "coulomb": dict(color=PALETTE[0], marker="o", ms=7, mfc="none", label="Coulomb"),
    "tanh": dict(color=PALETTE[1], marker="^", ms=3.5, ls="--", label="tanh"),
    "lugre": dict(color=PALETTE[2], marker="D", ms=4, ls=":", label="LuGre"),
}

#: The figures show displacements (m) in mm and voltages (V) in mV, as the paper does.
MILLI = 1e3

#: How each output channel is shown: its name on an axis and its SI unit.
CHANNEL_DISPLAY = {
    "relative_displacement": ("relative displacement z", "m"),
    "relative_velocity": ("relative velocity z'", "m/s"),
    "voltage": ("load voltage V", "V"),
    "current": ("load current i", "A"),
}


def display_scale(kind: str, values) -> tuple[float, str]:
    """(factor, unit) showing channel ``kind``: displacements in mm (the paper's), the
    others with the prefix (none, m, µ) that puts the largest value between 1 and 1000."""
    base = CHANNEL_DISPLAY[kind][1]
    if kind == "relative_displacement":
        return MILLI, "mm"
    largest = float(np.nanmax(np.abs(values))) if np.size(values) else 1.0
    for factor, prefix in ((1.0, ""), (1e3, "m"), (1e6, "µ")):
        if largest * factor >= 1.0:
            return factor, prefix + base
    return 1e6, "µ" + base


#: Measured data in black, the model's simulation dashed in vermilion.
MEASURED = dict(color="black", lw=1.0, label="measured")
SIMULATED = dict(color=PALETTE[1], lw=1.0, ls="--", label="simulated")


def _finish(fig, path):
    if path is not None:
        save_figure(fig, path, tracked=False)  # the caller checked the path (CLI --plot, --force)
    return fig


#: A legend above its axes, left (the panel's title is on the right): never over the data.
ABOVE = dict(loc="lower left", bbox_to_anchor=(0.0, 1.0), borderaxespad=0.2, frameon=False)


def plot_time_history(
    prediction,
    ax=None,
    *,
    window=None,
    scale=None,
    unit=None,
    residual_ax=None,
    kind=None,
    legend=True,
):
    """Measured (solid black) and simulated (dashed) output channel.

    The shown window is stated with the time axis (``t0 to t1 s of T s``).

    Parameters
    ----------
    prediction : randvib.identification.prediction.Prediction
    ax : matplotlib Axes, optional
        Drawn into a new styled figure when not given.
    window : (t0, t1), optional
        Time window (s) to show; default :func:`default_window`.
    scale, unit : float, str
        Display scaling of the output, by default :func:`display_scale`
        (a displacement in mm).
    residual_ax : matplotlib Axes, optional
        Where to draw the residual, measured less simulated, over the same
        window (a fit that misses shows there what it misses).
    kind : str, optional
        The channel shown (default the prediction's first scored one).
    legend : bool
        A legend above the axes (False: the figure has one elsewhere).
    """
    if ax is None:
        _, axes = new_figure(figsize=(7.0, 2.6))
        ax = axes[0, 0]
    rec = prediction.record
    kind = kind or prediction.outputs[0]
    measured, simulated = rec[kind], prediction.simulated(kind)
    label = CHANNEL_DISPLAY[kind][0]
    if scale is None or unit is None:
        scale, unit = display_scale(kind, measured)
    t = rec.time
    t0, t1 = window if window is not None else (0.0, default_window(rec, kind))
    sel = (t >= t0) & (t <= t1)
    ax.plot(t[sel], measured[sel] * scale, **MEASURED)
    ax.plot(t[sel], simulated[sel] * scale, **SIMULATED)
    ax.set_ylabel(f"{label} ({unit})")
    ax.set_xlim(t[sel][0], t[sel][-1])
    # the window shown, stated where the time axis is labelled
    shown = f"time (s); shown: {t[sel][0]:.3g} to {t[sel][-1]:.3g} s of {float(t[-1] - t[0]):.3g} s"
    cost = prediction.costs.get(kind, prediction.cost)
    ax.set_title(f"J = {cost:.3g} (Eq. 11)", loc="right")
    if legend:
        ax.legend(ncols=2, **ABOVE)
    if residual_ax is None:
        ax.set_xlabel(shown)
        return ax
    residual = (measured - simulated) * scale
    residual_ax.plot(t[sel], residual[sel], color=PALETTE[2], lw=0.8)
    residual_ax.axhline(0.0, color="black", lw=0.5)
    residual_ax.set_xlim(t[sel][0], t[sel][-1])
    residual_ax.set_xlabel(shown)
    residual_ax.set_ylabel(f"residual ({unit})")
    rms = float(np.sqrt(np.mean(residual**2)))
    residual_ax.set_title(f"measured - simulated, RMS {rms:.3g} {unit}", loc="right")
    return ax


def default_window(record, kind="relative_displacement", cycles=30.0, longest=2.0) -> float:
    """End (s) of the shown window: about ``cycles`` oscillations of the measured output.

    At most ``longest`` s, so that both curves stay readable whether the
    device rings at 5 Hz (2 s shown) or at 60 Hz (the Silverbox: 0.5 s); the
    oscillation rate is counted from the output's mean crossings.
    """
    values = record.z if kind == "relative_displacement" else record[kind]
    z = values - np.mean(values)
    crossings = np.count_nonzero(np.signbit(z[1:]) != np.signbit(z[:-1]))
    duration = float(record.time[-1] - record.time[0])
    if crossings < 2:
        return min(duration, longest)
    return min(duration, longest, cycles / (crossings / 2.0 / duration))


def histogram_bins(n: int) -> int:
    """Bins of a density histogram of ``n`` samples: ``2 n^(1/3)`` (Rice's rule), 10 to 81.

    Enough bins to show a density's shape, few enough that each holds many
    samples (81 bins of a 500-sample record would be noise).
    """
    return int(np.clip(np.ceil(2.0 * n ** (1.0 / 3.0)), 10, 81))


def histogram_panels(prediction, scale=None, unit=None) -> list:
    """(measured or None, simulated, name, unit) of each density panel: every scored
    channel, and the simulated load voltage of a device with a circuit.

    ``scale`` and ``unit`` apply to the first channel (default :func:`display_scale`)."""
    rec = prediction.record
    panels = []
    for kind in prediction.outputs:
        factor, shown = display_scale(kind, rec[kind])
        if kind == prediction.outputs[0] and scale is not None and unit is not None:
            factor, shown = scale, unit
        name = "z" if kind == "relative_displacement" else CHANNEL_DISPLAY[kind][0]
        panels.append((rec[kind] * factor, prediction.simulated(kind) * factor, name, shown))
    if prediction.voltage is not None and "voltage" not in prediction.outputs:
        factor, shown = display_scale("voltage", prediction.voltage)
        measured = None if rec.voltage is None else rec.voltage * factor
        panels.append((measured, prediction.voltage * factor, "load voltage V", shown))
    return panels


def plot_histograms(prediction, axes=None, *, bins=None, scale=None, unit=None, legend=True):
    """Densities of each measured and simulated channel and, with a coil, the load voltage.

    ``bins`` defaults to :func:`histogram_bins` of the record's length.

    With a circuit the voltage histogram shows the spike at zero volts caused
    by sticking (paper Figure 8b): while the magnet sticks, z' = 0 and so V = 0.
    ``legend=False`` leaves the legends out (a figure that has one elsewhere).
    """
    panels = histogram_panels(prediction, scale, unit)
    if axes is None:
        _, grid = new_figure(1, len(panels), figsize=(3.5 * len(panels), 2.6))
        axes = grid[0]
    axes = np.atleast_1d(axes)
    for ax, (meas, sim, name, unit_text) in zip(axes, panels, strict=False):
        values = [x for x in (meas, sim) if x is not None]
        lo = min(np.min(x) for x in values)
        hi = max(np.max(x) for x in values)
        edges = np.linspace(lo, hi, (bins or histogram_bins(len(sim))) + 1)
        if meas is not None:
            ax.hist(meas, edges, density=True, histtype="step", **MEASURED)
        ax.hist(sim, edges, density=True, histtype="step", **SIMULATED)
        ax.set_xlabel(f"{name} ({unit_text})")
        per = unit_text if "/" not in unit_text else f"({unit_text})"
        ax.set_ylabel(f"density (1/{per})")
        if legend:
            ax.legend(ncols=2, **ABOVE)
    return axes


def plot_residual_correlations(diagnostics, axes, *, legend=True) -> None:
    """Residual autocorrelation and its cross-correlation with the input, with bands.

    ``diagnostics`` is a
    :class:`~randvib.identification.residuals.ResidualDiagnostics`; the dashed
    lines are its (1 - LEVEL) bands of a white, independent residual (named
    in a legend above the first axes unless ``legend`` is False).
    """
    from randvib.identification.residuals import LEVEL

    ax_a, ax_c = axes
    band = f"{100 * (1 - LEVEL):g} % band"
    for ax, lags, r, half, name in (
        (ax_a, diagnostics.lags[1:], diagnostics.autocorrelation[1:], diagnostics.auto_band,
         f"residual autocorrelation ({diagnostics.verdict})"),
        (ax_c, diagnostics.cross_lags, diagnostics.cross_correlation, diagnostics.cross_band,
         "residual-input cross-correlation"),
    ):  # fmt: skip
        ax.vlines(lags, 0.0, r, color=PALETTE[0], lw=1.2)
        ax.axhline(half, color="black", ls="--", lw=0.8, label=band)
        ax.axhline(-half, color="black", ls="--", lw=0.8)
        ax.axhline(0.0, color="black", lw=0.5)
        ax.set_xlabel("lag (samples)")
        ax.set_ylabel("correlation")
        ax.set_title(name, loc="right", fontsize=8)
    if legend:
        ax_a.legend(**ABOVE)


@styled
def figure_fit(
    prediction,
    path=None,
    *,
    window=None,
    scale=None,
    unit=None,
    title=None,
    validation=None,
    diagnostics=None,
):
    """Paper Figure 8 analogue: (a) time history, (b) residual, then densities.

    The time history is of the first scored channel (the displacement, or
    the load voltage of a voltage fit); a density panel is drawn for each
    scored channel and for the simulated load voltage of a device with a
    circuit: a voltage's density shows the spike at 0 V of sticking.

    ``title`` defaults to the record's name; ``validation=True`` marks the
    figure as a validation (a record the model was not fitted to) in its
    title, ``False`` as the fit to its training record, None not at all.
    ``diagnostics`` (a
    :class:`~randvib.identification.residuals.ResidualDiagnostics`) adds a row
    with the residual's autocorrelation and its cross-correlation with the
    input (:func:`plot_residual_correlations`).
    """
    n_hist = len(histogram_panels(prediction))
    fig = _fit_layout(n_hist, diagnostics is not None)
    ax_t, ax_r, *rest = fig.axes
    plot_time_history(prediction, ax_t, window=window, scale=scale, unit=unit, residual_ax=ax_r,
                      legend=False)  # fmt: skip
    plot_histograms(prediction, rest[:n_hist], scale=scale, unit=unit, legend=False)
    handles, labels = ax_t.get_legend_handles_labels()
    if diagnostics is not None:
        plot_residual_correlations(diagnostics, rest[n_hist:], legend=False)
        more = rest[n_hist].get_legend_handles_labels()
        handles, labels = handles + more[0], labels + more[1]
    # one legend below the panels: inside (a) or (d) it covered the data
    fig.legend(handles, labels, loc="outside lower center", ncols=len(labels), frameon=False)
    panel_letters(fig.axes)
    what = {None: "", True: "validation: ", False: "fit to the training record: "}[validation]
    fig.suptitle(f"{what}{title if title else prediction.record.name}")
    return _finish(fig, path)


def _fit_layout(n_hist: int, correlations: bool = False):
    """The time history and its residual on top, ``n_hist`` histograms below, and
    with ``correlations`` a row of two residual-correlation panels."""
    import matplotlib.pyplot as plt

    rows = 4 if correlations else 3
    fig = plt.figure(figsize=(7.0, 8.4 if correlations else 6.4), layout="constrained")
    grid = fig.add_gridspec(rows, 2, height_ratios=(1.2, 0.8, 1.0, 1.0)[:rows])
    top = fig.add_subplot(grid[0, :])
    fig.add_subplot(grid[1, :], sharex=top)
    if n_hist == 1:
        fig.add_subplot(grid[2, :])
    else:
        row = grid[2, :].subgridspec(1, n_hist)
        for j in range(n_hist):
            fig.add_subplot(row[0, j])
    if correlations:
        fig.add_subplot(grid[3, 0])
        fig.add_subplot(grid[3, 1])
    return fig


@styled
def figure_costs(costs: dict, tests, path=None, *, titles=None):
    """Paper Figure 7 analogue: J per test for each model, one panel per training set.

    Parameters
    ----------
    costs : dict
        ``{training_label: {model: [J per test]}}``.
    tests : sequence of int
        Test numbers (x axis).
    titles : dict, optional
        Panel titles by training label (the panel letters are added).
    """
    n = len(costs)
    fig, axes = new_figure(1, n, figsize=(3.5 * n, 3.0), sharey=True)
    axes = axes[0]
    for ax, (label, table) in zip(axes, costs.items(), strict=True):
        for model, values in table.items():
            style = dict(MODEL_STYLE.get(model, dict(label=model)))
            style.setdefault("ls", "-")
            ax.semilogy(tests, values, lw=1, **style)
        ax.set_xlabel("test number")
        ax.set_xticks(list(tests))
        ax.set_title((titles or {}).get(label, label), loc="right")
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("cost J (Eq. 11)")
    panel_letters(axes)
    # one legend for all panels, outside them, so that no point is hidden
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncols=len(labels), frameon=False)
    return _finish(fig, path)
