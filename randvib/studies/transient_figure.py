"""Plot of a transient response: mean squares against time, Monte Carlo beside the analytic curve.

:func:`plot_transient` draws, against time, the mean-square displacement
E[z^2(t)], velocity E[z'^2(t)] and electrical power E[P_e(t)] of an event
from Monte Carlo (:class:`randvib.TransientResult`: markers with their 95 %
interval and a shaded band) and from the Lyapunov equation
(:class:`randvib.TransientPrediction`: a line), several labelled series at
once; a dotted line shows the envelope's intensity e(t)^2 on a second axis.
Journal layout: SI units on every axis (mm^2 and mW where they read better),
a legend, constrained layout.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled

#: (attribute, axis label, factor from SI) of the panels.
PANELS = {
    "displacement_variance": ("E[$z^2$] (mm$^2$)", 1e6),
    "velocity_variance": ("E[$\\dot z^2$] ((m/s)$^2$)", 1.0),
    "power_electrical": ("E[$P_e$] (mW)", 1e3),
}


@styled
def plot_transient(
    series: dict, *, quantities=tuple(PANELS), path: str | Path | None = None, envelope=True
):
    """Time-resolved mean squares of events: one panel per quantity, series overlaid.

    Parameters
    ----------
    series : dict
        Label -> result: a :class:`randvib.TransientResult` (Monte Carlo:
        markers, 95 % intervals and band), a
        :class:`randvib.TransientPrediction` (analytic: a line), or a tuple of
        them drawn in one colour (Monte Carlo beside its analytic curve).
    quantities : sequence of str
        Which panels, from ``displacement_variance``, ``velocity_variance``
        and ``power_electrical``.
    path : str or Path, optional
        Save the figure there (PNG) and close it; a
        :class:`randvib.figure_style.FigureLayoutWarning` first if texts overlap.
    envelope : bool
        Draw the first series' envelope intensity e(t)^2 (dotted, right axis).

    Returns
    -------
    matplotlib.figure.Figure or Path
        The figure, or the path it was saved to.
    """
    unknown = [q for q in quantities if q not in PANELS]
    if unknown:
        raise ValueError(f"`quantities` must be among {', '.join(PANELS)}; got {unknown}")
    if not series:
        raise ValueError("`series` is empty: give at least one label -> result")
    fig, axes = new_figure(len(quantities), 1, figsize=(6.5, 2.6 * len(quantities) + 0.6),
                           sharex=True)  # fmt: skip
    axes = axes[:, 0]
    series = {label: r if isinstance(r, tuple | list) else (r,) for label, r in series.items()}
    t_end = max(float(r.t_end) for group in series.values() for r in group)
    for i, (label, group) in enumerate(series.items()):
        colour = PALETTE[i % len(PALETTE)]
        for result in group:
            _draw(axes, quantities, label, result, colour)
    if envelope:
        first = next(iter(series.values()))[0]
        t = np.linspace(0.0, t_end, 1000)
        twin = axes[0].twinx()
        twin.plot(
            t, first.event.envelope(t) ** 2, ":", color="0.4", lw=1.0, label="$e(t)^2$ (right axis)"
        )
        twin.set_ylabel("$e(t)^2$", color="0.4")
        twin.set_ylim(bottom=0.0)
    # one legend, on the top-most axis: a second legend at the bottom hid the markers
    # where the response has decayed to zero
    handles, labels = axes[0].get_legend_handles_labels()
    top = axes[0]
    if envelope:
        more_handles, more_labels = twin.get_legend_handles_labels()
        handles, labels, top = handles + more_handles, labels + more_labels, twin
    top.legend(handles, labels, fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time since the event began (s)")
    axes[-1].set_xlim(0.0, t_end)
    panel_letters(axes)
    if path is None:
        return fig
    return save_figure(fig, path, tracked=False)  # a path the caller chose


def _draw(axes, quantities, label, result, colour) -> None:
    """One result on every panel: Monte Carlo as markers and band, analytic as a line."""
    times = np.asarray(result.times)
    for ax, name in zip(axes, quantities, strict=True):
        ylabel, factor = PANELS[name]
        values = getattr(result, name)
        if hasattr(values, "ci95"):  # Monte Carlo: TimeStatistics
            mean, half = factor * values.mean, factor * values.ci95
            ax.fill_between(times, mean - half, mean + half, color=colour, alpha=0.2, lw=0)
            ax.errorbar(times, mean, yerr=half, fmt="o", ms=3, capsize=2, color=colour,
                        label=f"{label} (Monte Carlo, 95 %)")  # fmt: skip
        else:
            ax.plot(times, factor * np.asarray(values), "-", color=colour, lw=1.4,
                    label=f"{label} (analytic)")  # fmt: skip
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, lw=0.5)
