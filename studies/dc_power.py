"""DC power through a diode bridge against the resistive figure: ``randvib study dc-power``.

(or ``python studies/dc_power.py OUT [--quick]``). How much of the power a
resistive load would take does a battery charged through a full-wave bridge
actually store? The paper's device (preset ``figure9``: m = 0.0226 kg, c_m =
0.1 Ns/m, k = 57.4 N/m, Coulomb Fc = 5.8 mN) with the paper's coil (alpha =
0.1992 Wb/m, R_C = 0.48 ohm), under white noise of level S:

- **resistive figure**: the coil into a matched load R_L = R_C, its load power;
- **bridge**: the coil into a full-wave bridge (inductance neglected) with a
  forward drop V_d per diode, charging a battery V_b; stored power V_b E|i|.

**Measured** by Monte Carlo, all circuits of a level on the same paths
(paired), with the energy-balance control variates; the ratio stored /
resistive with its 95 % interval. **Predicted** by the bridge's Gaussian
closure where it is offered, and its optimal battery voltage
(:func:`randvib.optimal_dc_output`) against Monte Carlo's best grid voltage.
"""

from __future__ import annotations

import sys

import randvib as rv
from randvib.figure_style import colour, new_figure, save_figure
from randvib.studies import bridge, report, script_main
from randvib.studies.grids import fixed_paths

NAME = "dc-power"
ALPHA, R_COIL = 0.1992, 0.48  #: the paper's coil (Wb/m, ohm)

__all__ = ["grid", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """Levels S, diode drops and battery voltages, Monte Carlo sizes."""
    if quick:
        return {"levels": (0.25, 1.0), "drops": (0.0, 0.02), "batteries": (0.01, 0.03, 0.06),
                "mc": dict(n_paths=32, window=4.0, burn_in=1.0, dt=2e-4)}  # fmt: skip
    return {"levels": (0.1, 0.25, 0.5, 1.0, 2.0, 4.0), "drops": (0.0, 0.02, 0.1, 0.3),
            "batteries": (0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2),
            "mc": dict(n_paths=256, window=20.0, burn_in=2.0, dt=2e-4)}  # fmt: skip


def verdicts(stored, optimum) -> dict:
    """The numbers behind the report's sentences."""
    over = bridge.overstatement(stored)
    offered = optimum.dropna(subset=["battery_optimal"])
    return {
        **over,
        "closure_largest_error": float((stored.closure / stored.power_stored - 1).abs().max())
        if stored.closure.notna().any()
        else None,
        "optima": {
            f"S={r.psd:g}, V_d={r.v_diode:g}": {
                "battery": float(r.battery_optimal),
                "where": r.optimum,
                "mc_best_battery": float(r.mc_best_battery),
            }
            for r in offered.itertuples()
        },  # fmt: skip
    }


def sentences(v: dict) -> list[str]:
    best = "; ".join(
        f"S = {s:g}: {b['ratio']:.3f} ± {b['ratio_ci95']:.3f} (V_d = {b['v_diode']:g} V, "
        f"V_b = {b['battery']:g} V)" for s, b in v["best_by_level"].items()
    )  # fmt: skip
    drops = "; ".join(
        f"V_d = {d:g} V: {b['ratio']:.3g} (S = {b['psd']:g}, V_b = {b['battery']:g} V)"
        for d, b in v["best_by_drop"].items()
    )  # fmt: skip
    factor = "n/a" if v["largest_factor"] is None else f"{v['largest_factor']:.3g}"
    return [
        f"The resistive figure overstates the stored power (paired 95 %) in "
        f"{v['n_overstated']} of {v['n_cases']} bridge cases, by up to a factor {factor} "
        f"where the stored power is resolved; the bridge never conducts in "
        f"{v['never_conducts']} of them.",
        f"Best stored / resistive ratio on the grid by level: {best}.",
        f"Best by diode drop: {drops}.",
    ]


def figure(stored, out):
    fig, axes = new_figure()
    ax = axes[0, 0]
    positive = stored.power_stored[stored.power_stored > 0]
    # a series that stores nothing cannot sit on a log axis: drawn hollow at a floor a
    # decade below the smallest stored power, and said so in the legend
    floor = 0.1 * float(positive.min()) if len(positive) else None
    hollow_drawn = False
    for i, (v_d, sub) in enumerate(stored.groupby("v_diode")):
        best = sub.loc[sub.groupby("psd").power_stored.idxmax()]
        zero = (best.power_stored <= 0).to_numpy()
        if not zero.all():  # markers only: each level's best V_b differs, nothing between
            ax.errorbar(best.psd[~zero], best.power_stored[~zero], best.power_stored_ci95[~zero],
                        marker="o", ls="none", color=colour(i),
                        label=f"bridge, V$_d$ = {v_d:g} V, best V$_b$")  # fmt: skip
        if zero.any() and floor is not None:
            hollow_drawn = True
            ax.plot(best.psd[zero], [floor] * int(zero.sum()), ls="none", marker="o",
                    color=colour(i), mfc="white",
                    label=f"bridge, V$_d$ = {v_d:g} V: stores 0 W (at the floor)")  # fmt: skip
    ref = stored.drop_duplicates("psd")
    # Monte Carlo at each level too: markers, not a line through levels never simulated
    ax.plot(ref.psd, ref.power_resistive, "kx", label="resistive figure (R$_L$ = R$_C$)")
    ax.set(xscale="log", yscale="log", xlabel="S ((m/s$^2$)$^2$/Hz)", ylabel="power (W)")
    if hollow_drawn:
        ax.axhline(floor, color="0.6", lw=0.6, ls=":")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside right upper", fontsize=7,
               title="markers: Monte Carlo with 95 % CI", title_fontsize=7)  # fmt: skip
    return save_figure(fig, out / "dc_power.png")


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True):
    """Run the study; write the tables, the figure, ``verdicts.json`` and ``report.md``."""
    g = grid(quick)
    base = rv.preset("figure9")
    settings = fixed_paths(**g["mc"], seed=seed, control_variates=True)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed})
    cases = bridge.bridge_cases(base, ALPHA, R_COIL, g["levels"], g["drops"], g["batteries"])
    result = rv.run_ensembles(cases, settings, out_dir=out / "ensembles", workers=workers,
                              scheduler=scheduler, progress=progress, name=NAME)  # fmt: skip
    stored = bridge.stored_table(result)
    optimum = bridge.optimum_table(base, ALPHA, R_COIL, g["levels"], g["drops"], stored)
    report.write_table(out, "stored.csv", stored)
    report.write_table(out, "optimum.csv", optimum)
    fig = figure(stored, out)
    v = verdicts(stored, optimum)
    said = sentences(v)
    report.write_verdicts(out, v, said)
    setup = (
        f"Device: preset `figure9` (m = 0.0226 kg assumed), the paper's coil (alpha = {ALPHA} "
        f"Wb/m, R_C = {R_COIL} ohm), white noise S = {', '.join(map(str, g['levels']))}; "
        f"V_d = {', '.join(map(str, g['drops']))} V; V_b = "
        f"{', '.join(map(str, g['batteries']))} V. Monte Carlo: {settings.min_paths} paths x "
        f"{settings.window:g} s after {settings.burn_in:g} s, dt = {settings.dt:g} s, Heun, "
        f"seed {seed}, control variates.{' Quick mode.' if quick else ''}\n\n"
        f"![stored power]({fig.name})"
    )
    return report.write_report(
        out,
        "DC power through a diode bridge",
        [
            ("Set-up", setup),
            ("Stored against resistive", " ".join(said) + "\n\n"
             + report.markdown_table(report.readable_table(stored))),
            ("Optimal battery voltage", report.markdown_table(report.readable_table(optimum))),
        ],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
