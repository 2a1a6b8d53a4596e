"""Plot of a transient response: what an event does, Monte Carlo beside the analytic curve.

:func:`plot_transient` draws, against time, the mean-square displacement
E[z^2(t)], the electrical power E[P_e(t)], the energy harvested since the
event began, and (for a device with a stroke) the probability that |z| has
reached the stroke, from Monte Carlo (:class:`randvib.TransientResult`:
markers with their 95 % interval and a shaded band; the energy of the whole
event as one marker at its end; a probability with its Wilson interval) and
from the Lyapunov equation (:class:`randvib.TransientPrediction`: lines; the
out-crossing approximations of the stroke, Poisson and Vanmarcke, dashed and
labelled approximate, with Rice's upper bound, the expected number of
out-crossings). A dotted line shows the envelope's intensity e(t)^2 on
a second axis whose zero is the first axis' zero. Journal layout: SI units on
every axis (mm^2, mW and mJ where they read better), one legend below the
panels (never over the data), constrained layout.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled

#: (axis label, factor from SI) of the panels.
PANELS = {
    "displacement_variance": ("E[$z^2$] (mm$^2$)", 1e6),
    "velocity_variance": ("E[$\\dot z^2$] ((m/s)$^2$)", 1.0),
    "power_electrical": ("E[$P_e$] (mW)", 1e3),
    "energy": ("energy since t = 0 (mJ)", 1e3),
    "stroke_reached": ("P(|z| reached the stroke)", 1.0),
}
#: The panels drawn by default; ``stroke_reached`` where a device has a stroke.
DEFAULT_PANELS = ("displacement_variance", "power_electrical", "energy", "stroke_reached")


@styled
def plot_transient(series: dict, *, quantities=None, path: str | Path | None = None, envelope=True):
    """Time-resolved response to events: one panel per quantity, series overlaid.

    Parameters
    ----------
    series : dict
        Label -> result: a :class:`randvib.TransientResult` (Monte Carlo:
        markers, 95 % intervals and band), a
        :class:`randvib.TransientPrediction` (analytic: a line), or a tuple of
        them drawn in one colour (Monte Carlo beside its analytic curve).
    quantities : sequence of str, optional
        Which panels, from ``displacement_variance``, ``velocity_variance``,
        ``power_electrical``, ``energy`` (harvested since t = 0: the analytic
        cumulative energy, Monte Carlo's energy of the whole event at its
        end) and ``stroke_reached`` (P(|z| has exceeded the stroke by t):
        Monte Carlo with its Wilson interval, the analytic out-crossing
        approximations). Default: all but the velocity, ``stroke_reached``
        only where a device has a stroke.
    path : str or Path, optional
        Save the figure there (PNG) and close it; a
        :class:`randvib.figure_style.FigureLayoutWarning` first if texts
        overlap or the legend covers data.
    envelope : bool
        Draw the first series' envelope intensity e(t)^2 (dotted, right axis).

    Returns
    -------
    matplotlib.figure.Figure or Path
        The figure, or the path it was saved to.
    """
    if not series:
        raise ValueError("`series` is empty: give at least one label -> result")
    series = {label: r if isinstance(r, tuple | list) else (r,) for label, r in series.items()}
    results = [r for group in series.values() for r in group]
    if quantities is None:
        stroke = any(r.harvester.stroke is not None for r in results)
        quantities = [q for q in DEFAULT_PANELS if stroke or q != "stroke_reached"]
    unknown = [q for q in quantities if q not in PANELS]
    if unknown:
        raise ValueError(f"`quantities` must be among {', '.join(PANELS)}; got {unknown}")
    fig, axes = new_figure(len(quantities), 1, figsize=(6.5, 2.2 * len(quantities) + 1.0),
                           sharex=True)  # fmt: skip
    axes = axes[:, 0]
    t_end = max(float(r.t_end) for r in results)
    for i, group in enumerate(series.values()):
        for result in group:
            _draw(axes, quantities, list(series)[i], result, PALETTE[i % len(PALETTE)])
    for ax in axes:  # mean squares, energies and probabilities start at 0
        ax.set_ylim(bottom=0.0)
    handles, labels = _legend_entries(axes)
    if envelope:
        _envelope(axes[0], results[0], t_end, handles, labels)
    # one legend below the panels: inside them it covered the data (the decay, the tail)
    fig.legend(handles, labels, loc="outside lower center", ncols=2, fontsize=7)
    axes[-1].set_xlabel("time since the event began (s)")
    axes[-1].set_xlim(0.0, 1.03 * t_end)  # room for the whole event's energy marker at t_end
    panel_letters(axes)
    if path is None:
        return fig
    return save_figure(fig, path, tracked=False)  # a path the caller chose


def _legend_entries(axes):
    """Every panel's labelled artists, each label once."""
    entries = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    return list(entries.values()), list(entries)


def _envelope(ax, first, t_end, handles, labels) -> None:
    """The envelope's intensity e(t)^2 on a right axis whose 0 is the left axis' 0."""
    t = np.linspace(0.0, t_end, 1000)
    twin = ax.twinx()
    (line,) = twin.plot(t, first.event.envelope(t) ** 2, ":", color="0.4", lw=1.0)
    twin.set_ylabel("$e(t)^2$", color="0.4")
    twin.set_ylim(0.0, 1.05 * max(float(np.max(first.event.envelope(t) ** 2)), 1e-300))
    twin.grid(False)
    handles.append(line)
    labels.append("$e(t)^2$ (right axis)")


def _draw(axes, quantities, label, result, colour) -> None:
    """One result on every panel: Monte Carlo as markers and band, analytic as a line."""
    times = np.asarray(result.times)
    monte_carlo = hasattr(result, "n_paths")
    for ax, name in zip(axes, quantities, strict=True):
        ylabel, factor = PANELS[name]
        ax.set_ylabel(ylabel)
        if name == "energy":
            _energy(ax, label, result, colour, factor, monte_carlo)
        elif name == "stroke_reached":
            _stroke(ax, label, result, colour, monte_carlo)
        elif monte_carlo:
            _statistic(
                ax, times, getattr(result, name), factor, colour, f"{label} (Monte Carlo, 95 %)"
            )
        else:
            ax.plot(times, factor * np.asarray(getattr(result, name)), "-", color=colour, lw=1.4,
                    label=f"{label} (analytic)")  # fmt: skip


def _statistic(ax, times, values, factor, colour, label) -> None:
    """Monte Carlo estimates at ``times``: markers with their 95 % interval and a band."""
    low, high = (np.asarray(end) for end in _ends(values))
    mean = factor * values.mean
    low, high = factor * low, factor * high
    ax.fill_between(times, low, high, color=colour, alpha=0.2, lw=0)
    ax.errorbar(times, mean, yerr=[mean - low, high - mean], fmt="o", ms=3, capsize=2,
                color=colour, label=label)  # fmt: skip


def _ends(values):
    """(lower, upper) of a TimeStatistics: a probability's Wilson interval, else mean +- ci95."""
    if getattr(values, "lower", None) is not None:
        return values.lower, values.upper
    return values.mean - values.ci95, values.mean + values.ci95


def _energy(ax, label, result, colour, factor, monte_carlo) -> None:
    """Energy harvested since t = 0: the analytic curve; Monte Carlo's whole event at its end."""
    if not monte_carlo:
        ax.plot(result.times, factor * np.asarray(result.cumulative_energy), "-", color=colour,
                lw=1.4, label=f"{label} (analytic)")  # fmt: skip
        return
    energy = result.energy_electrical
    ax.errorbar([result.t_end], [factor * energy.mean], yerr=[[factor * energy.ci95]] * 2,
                fmt="D", ms=4, capsize=3, color=colour,
                label=f"{label} (Monte Carlo, whole event, 95 %)")  # fmt: skip


def _stroke(ax, label, result, colour, monte_carlo) -> None:
    """P(stroke reached by t): Monte Carlo with its Wilson interval, the approximations dashed."""
    if result.harvester.stroke is None:
        return
    if monte_carlo:
        _statistic(ax, np.asarray(result.times), result.stroke_reached, 1.0, colour,
                   f"{label} (Monte Carlo, 95 %)")  # fmt: skip
        return
    # Vanmarcke's falls below Monte Carlo early in an event (the envelope's clumping is
    # the stationary one): Rice's bound, the expected out-crossings, is drawn above them
    for name, style, words in (("stroke_reached_poisson", "--", "Poisson, approximate"),
                               ("stroke_reached_vanmarcke", "-.", "Vanmarcke, approximate"),
                               ("stroke_reached_bound", (0, (5, 1, 1, 1, 1, 1)),
                                "Rice, an upper bound")):  # fmt: skip
        values = getattr(result, name, None)
        if values is not None:
            ax.plot(result.times, values, linestyle=style, color=colour, lw=1.1,
                    label=f"{label} ({words})")  # fmt: skip
    ax.set_ylim(top=1.02)
