"""Plot of response spectra: where the power comes from, and how the spring detunes.

:func:`plot_response_spectra` draws, against frequency, the base
acceleration's PSD and the device's displacement and velocity PSDs and the
electrical power's frequency distribution c_e S_v(f) (W/Hz), from
statistical linearisation (:class:`randvib.ResponseSpectra`) and/or Monte
Carlo (:class:`randvib.SampledSpectra`, with its 95 % band), several
labelled series at once (e.g. the device with and without its Duffing
spring). Journal layout: SI units on every axis, a legend, constrained
layout, logarithmic PSD axes; tones as lines (stems). :func:`spectra_against_linearisation`
simulates the series it draws: Monte Carlo and statistical linearisation
for each of several devices under one input.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled

_PANELS = (
    ("displacement", "$S_z$ (m$^2$/Hz)"),
    ("velocity", "$S_v$ ((m/s)$^2$/Hz)"),
    ("power", r"$c_e\,S_v$ (W/Hz)"),
)


def _line_bandwidth(series: dict) -> float:
    """The Hann window's noise bandwidth 1.5 / segment (Hz) of the first Monte Carlo series.

    A tone's line, of mean square P, reads as a Welch peak of height about
    P / B; drawn at that height the lines of both routes meet the sampled
    peaks. 1.5 / (4 s) without a Monte Carlo series.
    """
    for spectra in series.values():
        if hasattr(spectra, "segment_duration"):
            return 1.5 / float(spectra.segment_duration)
    return 1.5 / 4.0


def _draw_lines(axes, spectra, colour, sampled: bool, bandwidth: float, drawn) -> None:
    """A series' tones as stems at mean square / ``bandwidth`` in each panel (with 95 % bars)."""
    lines = getattr(spectra, "lines", None)
    if not lines:
        return
    f = np.asarray(lines["frequency"])
    for k, (ax, (name, _)) in enumerate(zip(axes, _PANELS, strict=True)):
        height = np.asarray(lines[name]) / bandwidth
        keep = height > 0
        marker = "o" if sampled else "D"
        ax.vlines(f[keep], 0.02 * height[keep], height[keep], color=colour, lw=0.8, alpha=0.7)
        ax.plot(
            f[keep], height[keep], marker, color=colour, ms=4, mfc="none" if not sampled else colour
        )
        if sampled:
            half = np.asarray(lines[f"{name}_ci95"])[keep] / bandwidth
            ax.errorbar(f[keep], height[keep], yerr=half, fmt="none", color=colour, lw=0.8)
        drawn[k].append((f[keep], height[keep]))


@styled
def plot_response_spectra(
    series: dict, *, excitation=None, f_max: float | None = None, path: str | Path | None = None
):
    """Response spectra in three panels (S_z, S_v, power density), series overlaid.

    Parameters
    ----------
    series : dict
        Label -> spectra: a :class:`randvib.ResponseSpectra` (drawn as a
        dashed line, "linearisation") or a :class:`randvib.SampledSpectra`
        (solid line with its shaded 95 % band, "Monte Carlo"). Under tones
        each series' lines are stems at their mean square divided by the
        Welch noise bandwidth 1.5 / segment (the height of their Welch peak;
        :func:`_line_bandwidth`), open diamonds from linearisation, dots with
        95 % bars from Monte Carlo.
    excitation : Excitation, optional
        Its PSD is drawn on a second axis of the power panel ((m/s^2)^2/Hz).
    f_max : float, optional
        Upper frequency of the axes (Hz); default four times the frequency of
        the first series' power peak (room for a third harmonic), at most the
        highest frequency given.
    path : str or Path, optional
        Save the figure there (PNG, :data:`randvib.figure_style.DPI` dpi) and close it;
        a :class:`randvib.figure_style.FigureLayoutWarning` first if texts overlap.

    Returns
    -------
    matplotlib.figure.Figure or Path
        The figure, or the path it was saved to.
    """

    fig, axes = new_figure(3, 1, figsize=(6.5, 8.0), sharex=True)
    axes = axes[:, 0]
    colours = PALETTE
    top, peak = 0.0, None
    drawn = [[] for _ in _PANELS]  # (frequency, values) per panel, for the axis limits
    bandwidth = _line_bandwidth(series)
    for i, (label, spectra) in enumerate(series.items()):
        colour = colours[i % len(colours)]
        sampled = hasattr(spectra, "velocity_ci95")
        f = np.asarray(spectra.frequency)
        top = max(top, float(f.max()))
        if peak is None:
            peak = float(f[np.argmax(np.asarray(spectra.power))])
            if getattr(spectra, "lines", None):  # room for the highest tone
                peak = max(peak, float(np.max(spectra.lines["frequency"])) / 2.0)
        _draw_lines(axes, spectra, colour, sampled, bandwidth, drawn)
        for ax, (name, ylabel) in zip(axes, _PANELS, strict=True):
            values = np.asarray(getattr(spectra, name))
            keep = values > 0  # log axes
            style = "-" if sampled else "--"
            ax.plot(f[keep], values[keep], style, color=colour, lw=1.2, label=label)
            drawn[_PANELS.index((name, ylabel))].append((f[keep], values[keep]))
            if sampled:
                half = np.asarray(getattr(spectra, f"{name}_ci95"))
                lo = np.maximum(values - half, values * 1e-3)
                ax.fill_between(f[keep], lo[keep], (values + half)[keep], color=colour, alpha=0.2)
            ax.set_ylabel(ylabel)
            ax.set_yscale("log")
            ax.grid(alpha=0.3, lw=0.5)  # major only: minor lines crowd a narrow log range
    if f_max is None:
        f_max = min(top, 4.0 * peak) if peak else top
    for ax, lines in zip(axes, drawn, strict=True):
        # the limits are the lines' within the shown band: not the tails beyond
        # f_max, not the Monte Carlo band's floor
        shown = np.concatenate([v[(f > 0) & (f <= f_max)] for f, v in lines] or [np.ones(1)])
        if shown.size:
            ax.set_ylim(0.5 * shown.min(), 2.0 * shown.max())
    handles, labels = axes[0].get_legend_handles_labels()
    if excitation is not None:
        # its own logarithmic axis: a linear twin would read as a scale for the log curves
        twin = axes[2].twinx()
        f = np.linspace(0.0, f_max, 2000)[1:]
        density = np.asarray(excitation.psd(f), dtype=float)
        keep = density > 0
        handles += twin.plot(f[keep], density[keep], ":", color="0.4", lw=1.0)
        labels.append("base excitation (right axis)")
        twin.set_yscale("log")
        twin.set_ylabel("$S_{\\ddot y}$ ((m/s$^2$)$^2$/Hz)", color="0.4")
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8,
               title="solid: Monte Carlo (95 % band); dashed: linearisation",
               title_fontsize=7)  # fmt: skip
    axes[-1].set_xlabel("frequency (Hz)")
    axes[-1].set_xlim(0.0, f_max)
    panel_letters(axes)
    if path is None:
        return fig
    return save_figure(fig, path, tracked=False)  # a path the caller chose


def spectra_against_linearisation(
    devices: dict, excitation, settings, path: str | Path, *, n_paths: int = 32,
    record_every: int = 10,
) -> Path:  # fmt: skip
    """:func:`plot_response_spectra` of Monte Carlo and statistical linearisation, per device.

    Each device of ``devices`` (label -> Harvester) is simulated under
    ``excitation`` with ``n_paths`` recorded paths (every ``record_every``-th
    step), on the step, window, burn-in, scheme and seed of ``settings`` (a
    :class:`randvib.SweepSettings`; the same paths for every device), and its
    Welch spectra (segments of at most 4 s, half the window) are drawn
    beside statistical linearisation's on the same frequencies.
    """
    from randvib.analytic.harmonic_linearisation import combined_linearisation
    from randvib.analytic.statistical_linearisation import statistical_linearisation
    from randvib.models.combined import as_input
    from randvib.montecarlo.simulation import simulate

    series = {}
    for label, device in devices.items():
        r = simulate(device, excitation, t_end=settings.burn_in + settings.window, dt=settings.dt,
                     n_paths=n_paths, burn_in=settings.burn_in, scheme=settings.scheme,
                     seed=settings.seed, record_paths=n_paths, record_every=record_every,
                     progress=False)  # fmt: skip
        mc = r.response_spectra(segment_duration=min(4.0, settings.window / 2))
        series[f"{label}, Monte Carlo"] = mc
        linearise = (
            combined_linearisation if as_input(excitation).lines() else statistical_linearisation
        )
        series[f"{label}, linearisation"] = linearise(device, excitation).response_spectra(
            mc.frequency
        )
    return plot_response_spectra(series, excitation=excitation, path=path)
