"""Harvesters on a host, arrays and two-mass harvesters: ``randvib study assemblies``.

(or ``python studies/assemblies.py OUT [--quick]``). Three questions of issue 31,
each answered with exact linear results where the device is linear (the
Lyapunov equation), statistical linearisation where it is not, and Monte
Carlo intervals (:mod:`randvib.studies.assembly_cases`):

(a) **When is the single-mass answer right?** A harvester tuned to one host
    mode (modal mass 1 kg, 10 Hz), damping ratios 0.01 mechanical and 0.04
    electrical, at mass ratios 0.1 % to 20 % of the host, for several host
    damping ratios, under white and band-pass input. The single-mass answer
    drives the harvester with the host's own vibration (measured without the
    harvester); the assembly's includes the harvester's reaction on the host.
    The mass ratio where the single-mass answer's error passes 5 % is found
    by root-finding on the exact answers; Monte Carlo of the assembly checks
    the exact answer at a few points.
(b) **Does an array of N detuned harvesters beat one tuned harvester** of the
    same total mass (5 % of the host), under band-pass input of varying
    bandwidth? Each harvester's spring and load are chosen by
    :func:`randvib.design` (exact Lyapunov search, a stroke budget on every
    harvester); the array and the single harvester are then simulated on the
    same paths and their powers compared pairwise.
(c) **A two-mass harvester against a single mass** of equal total mass
    (0.02 + 0.01 kg against 0.03 kg), with Coulomb friction on the magnet's
    coordinate, each designed by statistical linearisation (springs and load,
    a stroke budget on every moving coordinate), compared by Monte Carlo on
    the same paths.

Monte Carlo needs the assembly kernel (:mod:`randvib.montecarlo.assembly_simulation`):
a build without it (:func:`randvib.studies.assembly_cases.assembly_monte_carlo`)
runs the study on the exact and linearised answers alone, its Monte Carlo
columns NaN and its report saying so.

Every verdict is computed from the tables (:func:`randvib.studies.assembly_cases.single_mass_verdicts`,
``array_verdicts``, ``two_mass_verdicts``). Paired runs start from rest and
discard a burn-in of several of the slowest decay times, so that path i of
every device sees the same base excitation (a stationary start would draw a
different number of normals for devices of different sizes).
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.figure_style import colour, new_figure, save_figure
from randvib.studies import report, script_main
from randvib.studies.assembly_cases import (
    ANALYTIC_TIE,
    HostMode,
    array_verdicts,
    assembly_monte_carlo,
    harvesters_on_host,
    mass_ratio_at_error,
    paired_difference,
    single_mass_error,
    single_mass_harvester,
    single_mass_verdicts,
    total_power,
    tuned,
    two_mass_harvester,
    two_mass_verdicts,
)

NAME = "assemblies"
HOST_MASS, HOST_FREQUENCY = 1.0, 10.0  #: kg, Hz
HARVESTER = {"mechanical": 0.01, "electrical": 0.04}  #: damping ratios of (a)'s harvester
LEVEL = 0.1  #: S of every input of (a) and (b), (m/s^2)^2/Hz (a band-pass's peak)
ARRAY_MASS_RATIO, ARRAY_STROKE, EPS = 0.05, 0.02, 0.01  #: (b): total mu, stroke (m), budget
#: (c): outer and inner mass (kg), their dashpots' damping ratio at F0, stroke (m), level
OUTER, INNER, TWO_MASS_ZETA, TWO_MASS_STROKE, TWO_MASS_LEVEL = 0.02, 0.01, 0.01, 0.005, 1.0

#: The report's line where the build cannot simulate assemblies.
NO_MONTE_CARLO = (
    "No Monte Carlo: this build has no assembly kernel (randvib.montecarlo.assembly_simulation); "
    "every verdict above rests on the exact and linearised answers."
)

__all__ = ["grid", "run_study"]


def grid(quick: bool) -> dict:
    """The study's points and Monte Carlo sizes (``quick``: a few of each; ``mc`` None: none)."""
    if quick:
        return {
            "ratios": (1e-3, 1e-2, 0.05, 0.2), "host_zetas": (0.01, 0.05),
            "inputs": {"white": None, "band-pass zeta 0.1": 0.1},
            "checks": [("white", 0.05, 0.05)],
            "array_n": (1, 2), "bandwidths": (0.3,), "array_zeta": 0.02, "array_vary": ("k",),
            "two_mass_inputs": (0.3,), "fcs": (0.003,), "two_mass_vary": ("c_e",),
            "mc": {"n_paths": 32, "window": 3.0, "burn_in": 4.0, "dt": 2e-4},
        }  # fmt: skip
    return {
        "ratios": tuple(np.geomspace(1e-3, 0.2, 15)),
        "host_zetas": (0.005, 0.01, 0.02, 0.05, 0.1, 0.2),
        "inputs": {"white": None, "band-pass zeta 0.3": 0.3, "band-pass zeta 0.1": 0.1,
                   "band-pass zeta 0.03": 0.03},
        "checks": [("white", 0.02, 0.01), ("white", 0.02, 0.2), ("band-pass zeta 0.1", 0.02, 0.05),
                   ("band-pass zeta 0.03", 0.05, 0.2)],
        "array_n": (1, 2, 3), "bandwidths": (0.02, 0.05, 0.1, 0.3, 1.0), "array_zeta": 0.02,
        "array_vary": ("k", "c_e"),
        "two_mass_inputs": (0.05, 0.3), "fcs": (0.0, 0.001, 0.003), "two_mass_vary": ("k", "c_e"),
        "mc": {"n_paths": 256, "window": 20.0, "burn_in": 6.0, "dt": 2e-4},
    }  # fmt: skip


def excitation(zeta, level=LEVEL, frequency=HOST_FREQUENCY):
    """White noise of ``level`` (``zeta`` None), else band-pass at ``frequency``."""
    return rv.White(level) if zeta is None else rv.BandPass(level, frequency, zeta)


def simulate(assembly, x, mc: dict | None, seed: int):
    """Monte Carlo of an assembly from rest (paired runs: path i the same input for all).

    None where ``mc`` is None (no Monte Carlo).
    """
    if mc is None:
        return None
    return rv.simulate(assembly, x, t_end=mc["burn_in"] + mc["window"], dt=mc["dt"],
                       n_paths=mc["n_paths"], burn_in=mc["burn_in"], seed=seed,
                       initial="rest", progress=False)  # fmt: skip


def power_columns(run, name: str = "power_mc") -> dict:
    """{name, name_ci95, n_paths}: a run's total electrical power (W), NaN without a run."""
    if run is None:
        return {name: math.nan, f"{name}_ci95": math.nan, "n_paths": 0}
    power = total_power(run)
    return {name: power.mean, f"{name}_ci95": power.ci95, "n_paths": power.n_paths}


def difference_columns(a, b) -> dict:
    """{difference_mc, difference_mc_ci95}: run ``a``'s power minus ``b``'s, paired (W)."""
    if a is None or b is None:
        return {"difference_mc": math.nan, "difference_mc_ci95": math.nan}
    d = paired_difference(a, b)
    return {"difference_mc": d.mean, "difference_mc_ci95": d.ci95}


# ----------------------------------------------------------------------------- (a)
def single_mass_tables(g: dict, seed: int):
    """(errors, crossings, checks) of question (a)."""
    rows, crossings, checks = [], [], []
    for name, zeta in g["inputs"].items():
        x = excitation(zeta)
        for host_zeta in g["host_zetas"]:
            host = HostMode(HOST_MASS, HOST_FREQUENCY, host_zeta)
            for ratio in g["ratios"]:
                rows.append({"input": name, "host_zeta": host_zeta, "mass_ratio": ratio,
                             **single_mass_error(host, ratio, x, **HARVESTER)})  # fmt: skip
            ratio, where = mass_ratio_at_error(host, x, **HARVESTER)
            crossings.append({"input": name, "host_zeta": host_zeta,
                              "mass_ratio_crossing": ratio, "where": where})  # fmt: skip
    for name, host_zeta, ratio in g["checks"]:
        host = HostMode(HOST_MASS, HOST_FREQUENCY, host_zeta)
        m = ratio * host.mass
        k, c_m, c_e = tuned(host, m, **HARVESTER)
        x = excitation(g["inputs"][name])
        run = simulate(harvesters_on_host(host, [m], [k], [c_m], [c_e]), x, g["mc"], seed)
        exact = single_mass_error(host, ratio, x, **HARVESTER)
        checks.append({"input": name, "host_zeta": host_zeta, "mass_ratio": ratio,
                       "power_assembly": exact["power_assembly"],
                       "power_single_mass": exact["power_single_mass"], **power_columns(run)})  # fmt: skip
    return pd.DataFrame(rows), pd.DataFrame(crossings), pd.DataFrame(checks)


# ----------------------------------------------------------------------------- (b)
def array_design(n: int, bandwidth: float, host: HostMode, chosen=("k", "c_e")):
    """The analytic design of N harvesters of total mass ARRAY_MASS_RATIO M on the host.

    ``chosen``: each harvester's spring ``k`` (0.5 to 1.5 times the host's
    frequency) and load ``c_e`` (damping ratio 0.002 to 1); one not chosen
    stays tuned to the host with (a)'s damping ratios.
    """
    m = ARRAY_MASS_RATIO * host.mass / n
    k, c_m, c_e = tuned(host, m, **HARVESTER)
    device = harvesters_on_host(host, [m] * n, [k] * n, [c_m] * n, [c_e] * n, stroke=ARRAY_STROKE)
    ranges = {"k": (m * (0.5 * host.omega) ** 2, m * (1.5 * host.omega) ** 2),
              "c_e": (2 * 0.002 * m * host.omega, 2 * 1.0 * m * host.omega)}  # fmt: skip
    paths = {"k": "element.{i}.k", "c_e": "transducer.{i}.c_e"}
    vary = {paths[name].format(i=i): ranges[name] for i in range(n) for name in chosen}
    return rv.design(device, excitation(bandwidth), vary, exceedance=EPS, monte_carlo=False)


def array_table(g: dict, seed: int) -> pd.DataFrame:
    """Question (b): each bandwidth's single harvester and arrays, exact and Monte Carlo."""
    host = HostMode(HOST_MASS, HOST_FREQUENCY, g["array_zeta"])
    rows = []
    for bandwidth in g["bandwidths"]:
        runs = {}
        for n in g["array_n"]:
            result = array_design(n, bandwidth, host, g["array_vary"])
            runs[n] = simulate(result.device, excitation(bandwidth), g["mc"], seed)
            m = ARRAY_MASS_RATIO * host.mass / n
            rows.append({
                "bandwidth": bandwidth, "n": n, "power": result.power_predicted,
                "frequencies": " ".join(
                    f"{math.sqrt(result.device.get(f'element.{i}.k') / m) / (2 * math.pi):.3g}"
                    for i in range(n)),
                "loads": " ".join(f"{result.device.get(f'transducer.{i}.c_e'):.3g}"
                                  for i in range(n)),
                "exceedance": result.exceedance_predicted, **power_columns(runs[n]),
                **difference_columns(runs[n] if n != g["array_n"][0] else None,
                                     runs[g["array_n"][0]]),
            })  # fmt: skip
    table = pd.DataFrame(rows)
    first = table[table.n == g["array_n"][0]].set_index("bandwidth").power
    table["gain"] = table.power / table.bandwidth.map(first) - 1.0
    return table


# ----------------------------------------------------------------------------- (c)
def two_mass_designs(x, fc: float, chosen=("k", "c_e")):
    """(single, two-mass): each harvester's analytic design (linearisation) under ``x``.

    ``chosen``: the springs ``k`` (single: 0.5 to 2 times F0; two-mass: the
    outer 0.1 to 10 times the total mass's tuning, the inner 0.5 to 2 times
    F0) and the load ``c_e`` (0.01 to 3 Ns/m); a spring not chosen stays
    tuned to F0 (for the two-mass: outer and inner each on its own mass).
    """
    total, w = OUTER + INNER, 2 * math.pi * HOST_FREQUENCY
    single = single_mass_harvester(total, total * w**2, TWO_MASS_ZETA, HOST_FREQUENCY, fc, 0.1,
                                   TWO_MASS_STROKE)  # fmt: skip
    two = two_mass_harvester(OUTER, INNER, total * w**2, INNER * w**2, TWO_MASS_ZETA,
                             HOST_FREQUENCY, fc, 0.1, TWO_MASS_STROKE)  # fmt: skip
    loads = {"transducer.0.c_e": (0.01, 3.0)} if "c_e" in chosen else {}
    springs = "k" in chosen
    single_vary = {"structure.stiffness.0.0": (total * (0.5 * w) ** 2, total * (2 * w) ** 2)}
    two_vary = {"structure.stiffness.0.0": (0.1 * total * w**2, 10 * total * w**2),
                "element.1.k": (INNER * (0.5 * w) ** 2, INNER * (2 * w) ** 2)}  # fmt: skip
    with warnings.catch_warnings():  # the closure's validity warnings: Monte Carlo decides
        warnings.simplefilter("ignore", rv.LinearisationValidityWarning)
        a = rv.design(single, x, {**(single_vary if springs else {}), **loads}, exceedance=EPS,
                      monte_carlo=False)  # fmt: skip
        b = rv.design(two, x, {**(two_vary if springs else {}), **loads}, exceedance=EPS,
                      monte_carlo=False)  # fmt: skip
    return a, b


def two_mass_table(g: dict, seed: int) -> pd.DataFrame:
    """Question (c): each input and friction level, both designs and their paired Monte Carlo."""
    rows = []
    for zeta in g["two_mass_inputs"]:
        x = excitation(zeta, TWO_MASS_LEVEL)
        for fc in g["fcs"]:
            a, b = two_mass_designs(x, fc, g["two_mass_vary"])
            runs = [simulate(r.device, x, g["mc"], seed) for r in (a, b)]
            rows.append({
                "input": f"band-pass zeta {zeta:g}", "fc": fc,
                "power_single": a.power_predicted, "power_two_mass": b.power_predicted,
                "exact": bool(fc == 0), **power_columns(runs[0], "single_mc"),
                **power_columns(runs[1], "two_mass_mc"), **difference_columns(runs[1], runs[0]),
                "single_k": a.device.get("structure.stiffness.0.0"),
                "single_c_e": a.device.get("transducer.0.c_e"),
                "two_mass_k_outer": b.device.get("structure.stiffness.0.0"),
                "two_mass_k_inner": b.device.get("element.1.k"),
                "two_mass_c_e": b.device.get("transducer.0.c_e"),
            })  # fmt: skip
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- words
def sentences(a: dict, b: dict, c: dict) -> list[str]:
    """The report's verdicts, every number from the verdict dictionaries."""
    crossed = {k: v for k, v in a["crossings"].items() if a["crossing_where"][k] == "crossed"}
    below = [k for k, w in a["crossing_where"].items() if w == "below"]
    said = [
        f"(a) The single-mass answer {'overestimates' if a['overestimates_everywhere'] else 'misses'} "
        f"the assembly's power {'everywhere' if a['overestimates_everywhere'] else 'in places'}; "
        f"at the smallest mass ratio, {100 * a['smallest_mass_ratio']:.2g} %, it is within "
        f"{100 * a['threshold']:g} % in {len(a['right_at_smallest_ratio'])} of {a['cases']} cases, "
        f"and the largest error is {100 * a['largest_error']:.3g} %.",
        "(a) Its error passes 5 % at mass ratio "
        + "; ".join(f"{k}: {100 * v:.3g} %" for k, v in crossed.items())
        + (f"; already below 1e-8 for {', '.join(below)}" if below else "")
        + (". The crossing grows with the host's damping" if a["crossing_grows_with_host_damping"]
           else ". The crossing does not grow with the host's damping everywhere")
        + "; in units of zeta_h zeta_a (zeta_a = "
        + f"{a['harvester_zeta']:g}, the harvester's damping ratio) it is "
        + "; ".join(f"{k}: {lo:.3g} to {hi:.3g}" for k, (lo, hi) in a["crossing_over_damping"].items())
        + ".",
        f"(a) Monte Carlo of the assembly agrees with the exact answer (|z| <= 3) at "
        f"{a['monte_carlo_agree']} of {a['monte_carlo_checks']} points.",
        f"(b) On the exact optima an array beats one tuned harvester of the same mass in "
        f"{b['array_better_exact']} of {b['comparisons']} comparisons (equal, within "
        f"{ANALYTIC_TIE:g}, in {b['array_equal_exact']}); the largest gain is "
        f"{100 * b['largest_gain']:.3g} %: "
        + "; ".join(f"zeta {bw}: best N = {v['best_n']} (+{100 * v['best_gain']:.3g} %)"
                    for bw, v in b["by_bandwidth"].items()) + ".",
        f"(b) Monte Carlo (paired 95 %): the array significantly better in "
        f"{b['array_significantly_better']} of {b['monte_carlo_comparisons']} comparisons, "
        f"worse in {b['single_significantly_better']}.",
        f"(c) By the analytic answers (exact without friction, else linearisation) the two-mass "
        f"harvester harvests more than the single mass in "
        f"{c['two_mass_better_linearisation']} of {len(c['cases'])} cases: "
        + "; ".join(f"{k}: ratio {v['ratio_predicted']:.3g}" for k, v in c["cases"].items()) + ".",
        f"(c) Monte Carlo (paired 95 %): the two-mass harvester significantly better in "
        f"{c['two_mass_better']} of {c['monte_carlo_cases']} cases, worse in {c['single_better']}"
        + "".join(f"; {k}: ratio {v['ratio_monte_carlo']:.3g}" for k, v in c["cases"].items()
                  if v["ratio_monte_carlo"] is not None)
        + ("" if c["linearisation_largest_error"] is None else
           f". Linearisation's largest error against Monte Carlo: "
           f"{100 * c['linearisation_largest_error']:.3g} %") + ".",
    ]  # fmt: skip
    if not a["monte_carlo_checks"] + b["monte_carlo_comparisons"] + c["monte_carlo_cases"]:
        said = [line for line in said if "Monte Carlo" not in line]
        said.append(NO_MONTE_CARLO)
    return said


def figures(errors, arrays, pairs, out: Path) -> Path:
    """Error against mass ratio (one panel per input); array gains; two-mass against single."""
    inputs = list(dict.fromkeys(errors.input))
    fig, axes = new_figure(1, len(inputs) + 2, figsize=(4.2 * (len(inputs) + 2), 3.8))
    for ax, name in zip(axes[0], inputs, strict=False):
        for i, (host_zeta, sub) in enumerate(errors[errors.input == name].groupby("host_zeta")):
            ax.plot(100 * sub.mass_ratio, 100 * sub.error.abs(), marker="o", ms=3,
                    color=colour(i), label=rf"$\zeta_h$ = {host_zeta:g}")  # fmt: skip
        ax.axhline(5.0, color="0.4", ls="--", lw=0.8, label="5 %")
        ax.set(xscale="log", yscale="log", xlabel="mass ratio (%)",
               ylabel="single-mass error (%)", title=name)  # fmt: skip
        ax.legend(fontsize=7, title="host damping (exact)", title_fontsize=7)
    array_panel(axes[0, len(inputs)], arrays)
    two_mass_panel(axes[0, len(inputs) + 1], pairs)
    return save_figure(fig, out / "assemblies.png")


def array_panel(ax, arrays) -> None:
    """The arrays' gain over one harvester: exact (open markers) and paired Monte Carlo."""
    single = arrays[arrays.n == arrays.n.min()].set_index("bandwidth").power_mc
    for i, (n, sub) in enumerate(arrays[arrays.n > arrays.n.min()].groupby("n")):
        scale = 100 / sub.bandwidth.map(single)
        ax.errorbar(sub.bandwidth, scale * sub.difference_mc, scale * sub.difference_mc_ci95,
                    marker="o", capsize=2, color=colour(i),
                    label=f"N = {n}, Monte Carlo (paired)")  # fmt: skip
        ax.plot(sub.bandwidth, 100 * sub.gain, ls="--", marker="s", mfc="none", ms=7,
                color=colour(i), label=f"N = {n}, exact optimum")  # fmt: skip
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.set(xscale="log", xlabel=r"input bandwidth $\zeta$", ylabel="gain over one harvester (%)",
           title="array of N against one")  # fmt: skip
    ax.legend(fontsize=7)


def two_mass_panel(ax, pairs) -> None:
    """Both devices' powers per case: Monte Carlo with 95 % intervals, linearisation open."""
    labels = [
        f"{r.input.replace('band-pass ', '')}\nFc {1e3 * r.fc:g} mN" for r in pairs.itertuples()
    ]
    where = np.arange(len(pairs))
    for i, (shift, column, predicted, label) in enumerate((
        (-0.15, "single_mc", "power_single", "single mass"),
        (0.15, "two_mass_mc", "power_two_mass", "two-mass"),
    )):  # fmt: skip
        ax.errorbar(where + shift, 1e3 * pairs[column], 1e3 * pairs[f"{column}_ci95"], ls="none",
                    marker="o", capsize=2, color=colour(i), label=f"{label}, Monte Carlo")  # fmt: skip
        ax.plot(where + shift, 1e3 * pairs[predicted], ls="none", marker="s", mfc="none", ms=7,
                color=colour(i), label=f"{label}, linearisation")  # fmt: skip
    ax.set_xticks(where, labels, fontsize=7)
    ax.set(ylabel="power (mW)", title="two-mass against single mass", xlim=(-0.6, len(pairs) - 0.4))
    ax.legend(fontsize=7)


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the assemblies study; write the tables, ``assemblies.png``, ``verdicts.json``, ``report.md``.

    ``workers`` and ``scheduler`` are not used: every run is in this process.
    """
    g = grid(quick)
    if not assembly_monte_carlo():
        g = {**g, "mc": None}
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed})
    started = time.perf_counter()
    errors, crossings, checks = single_mass_tables(g, seed)
    arrays = array_table(g, seed)
    pairs = two_mass_table(g, seed)
    for name, table in (("single_mass.csv", errors), ("crossings.csv", crossings),
                        ("checks.csv", checks), ("arrays.csv", arrays), ("two_mass.csv", pairs)):  # fmt: skip
        report.write_table(out, name, table)
    zeta_a = HARVESTER["mechanical"] + HARVESTER["electrical"]
    v = {"single_mass": single_mass_verdicts(errors, crossings, checks, zeta_a),
         "arrays": array_verdicts(arrays), "two_mass": two_mass_verdicts(pairs)}  # fmt: skip
    said = sentences(v["single_mass"], v["arrays"], v["two_mass"])
    report.write_verdicts(out, v, said)
    fig = figures(errors, arrays, pairs, out)
    return write(out, g, quick, seed, said, (errors, crossings, checks, arrays, pairs), fig,
                 time.perf_counter() - started)  # fmt: skip


def write(out, g, quick, seed, said, tables, fig, wall) -> Path:
    """The report: set-up, verdicts, then each question's tables."""
    errors, crossings, checks, arrays, pairs = tables
    mc = g["mc"]
    simulated = (
        f"Monte Carlo: Heun, dt = {mc['dt']:g} s, {mc['n_paths']} paths x {mc['window']:g} s "
        f"after {mc['burn_in']:g} s from rest, seed {seed} (one seed for all: paired)."
        if mc else "No Monte Carlo (no assembly kernel in this build)."
    )  # fmt: skip
    setup = (
        f"Host mode: {HOST_MASS:g} kg, {HOST_FREQUENCY:g} Hz. (a) harvester tuned to it, damping "
        f"ratios {HARVESTER['mechanical']:g} (mechanical) and {HARVESTER['electrical']:g} "
        f"(electrical); inputs white or band-pass at {HOST_FREQUENCY:g} Hz, S = {LEVEL:g} "
        f"(m/s^2)^2/Hz. (b) N harvesters of total mass ratio {ARRAY_MASS_RATIO:g} on the host "
        f"(zeta_h = {g['array_zeta']:g}), stroke {1e3 * ARRAY_STROKE:g} mm each, budget {EPS:g}. "
        f"(c) {OUTER:g} + {INNER:g} kg against {OUTER + INNER:g} kg, dashpots of damping ratio "
        f"{TWO_MASS_ZETA:g}, Coulomb friction on the magnet's coordinate, stroke "
        f"{1e3 * TWO_MASS_STROKE:g} mm on every moving coordinate, budget {EPS:g}, band-pass "
        f"S = {TWO_MASS_LEVEL:g}. {simulated} "
        f"{'Quick mode. ' if quick else ''}Wall time {wall:.0f} s.\n\n"
        f"![assemblies]({fig.name})"
    )
    table = report.markdown_table
    return report.write_report(
        out, f"Study {NAME}: harvesters on a host, arrays, two masses{' (quick)' * quick}",
        [("Set-up", setup), ("Verdicts", "\n".join(f"- {s}" for s in said)),
         ("(a) The single-mass answer", table(crossings) + "\n\n" + table(checks)),
         ("(b) Arrays", table(arrays)), ("(c) Two masses", table(pairs))],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
