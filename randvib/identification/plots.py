"""Figures for identification results (paper Figures 7 and 8).

Numbers come from :mod:`randvib.identification.fitting` (``Prediction`` objects and
cost tables); these functions only draw them.
"""

from __future__ import annotations

import numpy as np

MODEL_STYLE = {
    "viscous": dict(color="tab:gray", marker="s", label="no friction (viscous)"),
    "coulomb": dict(color="tab:blue", marker="o", label="Coulomb"),
    "tanh": dict(color="tab:orange", marker="^", label="tanh"),
    "lugre": dict(color="tab:green", marker="D", label="LuGre"),
}


def _pyplot():
    import matplotlib

    matplotlib.use(matplotlib.get_backend())
    import matplotlib.pyplot as plt

    return plt


def plot_time_history(prediction, ax=None, *, window=None, scale=1.0, unit="m"):
    """Measured (solid) and simulated (dashed) relative displacement.

    Parameters
    ----------
    prediction : randvib.identification.fitting.Prediction
    ax : matplotlib Axes, optional
    window : (t0, t1), optional
        Time window (s) to show; default the first 2 s.
    scale, unit : float, str
        Display scaling, e.g. ``1e3, "mm"``.
    """
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 3))
    rec = prediction.record
    t = rec.time
    t0, t1 = window if window is not None else (0.0, min(t[-1], 2.0))
    sel = (t >= t0) & (t <= t1)
    ax.plot(t[sel], rec.z[sel] * scale, "k-", lw=1.2, label="measured")
    ax.plot(t[sel], prediction.z[sel] * scale, "r--", lw=1.2, label="simulated")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"relative displacement ({unit})")
    ax.set_title(f"{rec.name}: J = {prediction.cost:.3g}")
    ax.legend(loc="upper right", fontsize="small")
    ax.grid(alpha=0.3)
    return ax


def plot_histograms(prediction, axes=None, *, bins=81, scale=1.0, unit="m"):
    """Histograms of measured and simulated displacement and, if present, load voltage.

    With a circuit the voltage histogram shows the spike at zero volts caused
    by sticking (paper Figure 8b): while the magnet sticks, z' = 0 and so V = 0.
    """
    plt = _pyplot()
    rec = prediction.record
    panels = [(rec.z * scale, prediction.z * scale, f"z ({unit})")]
    if prediction.voltage is not None:
        measured = None if rec.voltage is None else rec.voltage * 1e3
        panels.append((measured, prediction.voltage * 1e3, "load voltage (mV)"))
    if axes is None:
        _, axes = plt.subplots(1, len(panels), figsize=(4.5 * len(panels), 3.2))
    axes = np.atleast_1d(axes)
    for ax, (meas, sim, label) in zip(axes, panels, strict=False):
        values = [x for x in (meas, sim) if x is not None]
        lo = min(np.min(x) for x in values)
        hi = max(np.max(x) for x in values)
        edges = np.linspace(lo, hi, bins + 1)
        if meas is not None:
            ax.hist(meas, edges, density=True, histtype="step", color="k", lw=1.4, label="measured")
        ax.hist(
            sim, edges, density=True, histtype="step", color="r", ls="--", lw=1.4, label="simulated"
        )
        ax.set_xlabel(label)
        ax.set_ylabel("probability density")
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
    return axes


def figure_fit(prediction, path=None, *, window=None, scale=1.0, unit="m", title=None):
    """Paper Figure 8 analogue: time history and histograms in one figure."""
    plt = _pyplot()
    n_hist = 2 if prediction.voltage is not None else 1
    fig = plt.figure(figsize=(11, 6.5), constrained_layout=True)
    grid = fig.add_gridspec(2, n_hist)
    ax_t = fig.add_subplot(grid[0, :])
    plot_time_history(prediction, ax_t, window=window, scale=scale, unit=unit)
    axes = [fig.add_subplot(grid[1, j]) for j in range(n_hist)]
    plot_histograms(prediction, axes, scale=scale, unit=unit)
    if title:
        fig.suptitle(title)
    if path is not None:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig


def figure_costs(costs: dict, tests, path=None, *, titles=None):
    """Paper Figure 7 analogue: J per test for each model, one panel per training set.

    Parameters
    ----------
    costs : dict
        ``{training_label: {model: [J per test]}}``.
    tests : sequence of int
        Test numbers (x axis).
    """
    plt = _pyplot()
    n = len(costs)
    fig, axes = plt.subplots(1, n, figsize=(6 * n, 4), sharey=True, constrained_layout=True)
    axes = np.atleast_1d(axes)
    for ax, (label, table) in zip(axes, costs.items(), strict=True):
        for model, values in table.items():
            style = MODEL_STYLE.get(model, {})
            ax.semilogy(tests, values, ls="-", lw=1, ms=6, **style)
        ax.set_xlabel("test number")
        ax.set_xticks(list(tests))
        ax.set_title((titles or {}).get(label, label))
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("cost J (Eq. 11)")
    axes[0].legend(fontsize="small")
    if path is not None:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig


def figure_convergence(histories: dict, path=None, *, title=None):
    """Best cost against simulations spent, one line per optimiser/run."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    for label, (nfev, best) in histories.items():
        ax.loglog(nfev, best, label=label)
    ax.set_xlabel("simulations")
    ax.set_ylabel("best cost J")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize="small")
    if title:
        ax.set_title(title)
    if path is not None:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig
