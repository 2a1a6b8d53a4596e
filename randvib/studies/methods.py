"""Analytic methods against Monte Carlo, and the criteria for a fast method.

At one point (device, S) :func:`analytic_powers` gives E[P_e] by every
analytic method: equivalent linearisation (Eq. 32), stochastic averaging
(:mod:`randvib.analytic.averaging`), the fast corrected FPK grids
(``method="fpk-fast"``) and the FPK reference grid solution.
:func:`kappa_cases` puts several Duffing stiffnesses k3 of one (S, kappa) in
one group of :func:`randvib.run_ensembles` (the same Brownian paths;
stochastic Heun with the energy-identity and friction-free-companion control
variates), so that :func:`paired_k3_table` gives the change of power with k3,
P(Fc, k3) / P(Fc, k3_0) - 1, with a paired 95 % interval, beside every
method's power; :func:`errors_against_mc` adds the methods' relative errors
and k3 changes.

The accuracy criteria for a fast method (:func:`fast_method_verdicts`):
speed (one point under 10 ms, a 100-point sweep under 1 s, timed by
:func:`time_methods`), at most a third of linearisation's error where that
exceeds 3 %, at most 5 % everywhere, and the k3 interaction's sign and size
inside the Monte Carlo interval. The Coulomb level is set by the
dimensionless kappa = 4 Fc^2 / (pi S m c) (the group of paper Eq. 30: Eq. 32
halves the power at kappa = 1/4).

At the points of a sweep (:func:`randvib.run_sweep`): :func:`method_errors`
(each method's error against Monte Carlo, and averaging's validity).

For the cases of a paired run (:func:`randvib.run_ensembles`), any device,
input and stroke: :func:`methods_against_monte_carlo` (every method's power
and stroke exceedance against Monte Carlo, or why it refused),
:func:`method_accuracy` and :func:`accuracy_sentences` (its summary),
:func:`methods_shown` (its table for a report), and
:func:`linearisation_against_monte_carlo` (statistical linearisation with its
equivalent stiffness and damping); :func:`relative_error` is their error.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pandas as pd

from randvib.analytic.averaging import AveragingValidityWarning, averaging_statistics
from randvib.analytic.fokker_planck import fast_fpk_statistics, fpk_statistics
from randvib.analytic.linearisation import equivalent_damping
from randvib.analytic.prediction import expected_power, predict
from randvib.analytic.statistical_linearisation import statistical_linearisation
from randvib.formatting import plus_minus
from randvib.models.presets import preset
from randvib.montecarlo.ensembles import Case
from randvib.montecarlo.step_check import step_bias
from randvib.montecarlo.sweep import linearisation_verdicts, point_device
from randvib.studies.report import markdown_table

#: Analytic methods: column suffix -> (method name in randvib.METHODS, label).
ANALYTIC = {
    "linearisation": ("linearisation", "linearisation (Eq. 32)"),
    "averaging": ("averaging", "averaging"),
    "fpk_fast": ("fpk-fast", "fast FPK"),
    "fpk": ("fpk", "FPK grid (reference)"),
}
#: The fast methods judged against the accuracy criteria for a fast method.
CANDIDATES = ("averaging", "fpk_fast")
#: The speed bars for a fast method: one point (s) and a 100-point sweep (s).
POINT_BAR, SWEEP_BAR = 10e-3, 1.0
#: Finest grid of the FPK reference, cells per direction
#: (:func:`randvib.analytic.fokker_planck.fpk_statistics`).
FPK_REFERENCE_CELLS = 160


def fc_of_kappa(kappa, psd, device):
    """Coulomb level Fc (N) for the friction level kappa = 4 Fc^2/(pi S m c)."""
    return float(np.sqrt(kappa * np.pi * psd * device.m * device.c / 4.0))


def analytic_powers(device, psd) -> dict:
    """E[P_e] (W) by every method of :data:`ANALYTIC` at one point, and averaging's
    zeta_eff and zeta_friction (its validity: zeta_f <= 0.5)."""
    c_e = device.c_e
    lin_vv = psd * device.m / (4.0 * float(equivalent_damping(device, psd)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        avg = averaging_statistics(device, psd)
    fpk_vv = fpk_statistics(device, psd, FPK_REFERENCE_CELLS)[0]
    return {
        "power_linearisation": c_e * lin_vv,
        "power_averaging": c_e * avg.velocity_variance,
        "power_fpk_fast": c_e * fast_fpk_statistics(device, psd)[0],
        "power_fpk": c_e * fpk_vv,
        "zeta_eff": avg.zeta_eff,
        "zeta_friction": avg.zeta_friction,
    }


def kappa_cases(base, psds, kappas, k3s) -> list:
    """The cases of the methods' comparison: ``base`` at every (S, kappa, k3), white noise.

    One :class:`randvib.Case` per point, labelled ``psd``, ``kappa`` and
    ``k3``, with Fc from kappa (:func:`fc_of_kappa`); the k3 values of one
    (S, kappa) form a group (the same Brownian paths: the change of power
    with k3 is paired). Groups come S by S, then kappa.
    """
    return [Case({"psd": psd, "kappa": kappa, "k3": k3}, base.updated(k3=k3, fc=fc_of_kappa(
        kappa, psd, base)), psd, group=(psd, kappa)) for psd in psds for kappa in kappas
        for k3 in k3s]  # fmt: skip


def paired_k3_table(run) -> pd.DataFrame:
    """Every case of :func:`kappa_cases` run by :func:`randvib.run_ensembles`, with every method.

    Per case: ``psd``, ``kappa``, ``fc`` (N), ``k3``, the Monte Carlo power
    ``power_mc`` with its 95 % half-width, the linearised step bias of the
    run's scheme and step, ``n_paths``, ``mc_seconds`` (wall time),
    :func:`analytic_powers`, and ``dk3_mc``: the paired change
    P(k3) / P(k3_0) - 1 against the smallest k3 of the run, with its 95 %
    half-width (the run's control variates in the paired estimate); then
    :func:`errors_against_mc`.
    """
    t, settings = run.table, run.settings
    k3_0, rows = float(t.k3.min()), []
    for i, case in enumerate(run.cases):
        device, psd = case.device, case.excitation
        row = {"psd": psd, "kappa": case.labels["kappa"], "fc": float(device.friction.fc),
               "k3": case.labels["k3"], "power_mc": t.power_electrical[i],
               "power_mc_ci95": t.power_electrical_ci95[i],
               "step_bias": abs(step_bias(settings.scheme, device, psd, settings.dt)),
               "n_paths": t.n_paths[i], "mc_seconds": t.wall_time[i],
               **analytic_powers(device, psd)}  # fmt: skip
        ref = run.partner(i, k3=k3_0)
        change = run.paired({i: 1.0, ref: -1.0}) if ref != i else None
        row["dk3_mc"] = 0.0 if change is None else change.mean / t.power_electrical[ref]
        row["dk3_mc_ci95"] = 0.0 if change is None else change.ci95 / t.power_electrical[ref]
        rows.append(row)
    return errors_against_mc(pd.DataFrame(rows))


def errors_against_mc(df: pd.DataFrame) -> pd.DataFrame:
    """Errors against MC and the analytic k3 changes P(k3)/P(k3_min) - 1 per (S, kappa)."""
    df = df.copy()
    ref = df.groupby(["psd", "kappa"])["k3"].transform("min")
    base = df[df["k3"] == ref].set_index(["psd", "kappa"])
    key = pd.MultiIndex.from_frame(df[["psd", "kappa"]])
    for name in ANALYTIC:
        df[f"err_{name}"] = df[f"power_{name}"] / df["power_mc"] - 1.0
        df[f"dk3_{name}"] = df[f"power_{name}"] / base[f"power_{name}"].reindex(key).values - 1.0
    df["mc_rel_ci95"] = df["power_mc_ci95"] / df["power_mc"]
    return df


def time_methods(k3s, repeats: int = 3) -> dict:
    """Best wall time (s) of one point and of a 100-point broadcast sweep per candidate.

    The point is the figure9 device at S = 1, kappa = 1, k3 = 5e5; the sweep
    covers kappa in [0, 2] (25 levels) x the four ``k3s`` (N/m^3) at S = 1.
    """
    base = preset("figure9")
    point = base.updated(k3=5e5, fc=fc_of_kappa(1.0, 1.0, base))
    fc = np.array([fc_of_kappa(x, 1.0, base) for x in np.linspace(0.0, 2.0, 25)])
    sweep = base.updated(fc=fc[None, :], k3=np.array(k3s)[:, None])
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        for name in CANDIDATES:
            method = ANALYTIC[name][0]
            for label, device in (("point", point), ("sweep100", sweep)):
                best = np.inf
                for _ in range(repeats):
                    started = time.perf_counter()
                    expected_power(device, 1.0, method)
                    best = min(best, time.perf_counter() - started)
                out[f"{name}_{label}_s"] = best
    return out


def k3_change_interval(df: pd.DataFrame) -> tuple[pd.DataFrame, pd.Series]:
    """The rows with k3 above the smallest, and the half-width that judges their k3 change.

    The Monte Carlo 95 % interval of the paired change, widened by the two
    runs' time-step bias bounds (the pairing does not cancel them exactly).
    """
    inter = df[df["k3"] > df["k3"].min()]
    return inter, inter["dk3_mc_ci95"] + inter["step_bias"] + df["step_bias"].min()


def fast_method_verdicts(df: pd.DataFrame, timings: dict | None = None) -> dict:
    """The accuracy criteria for a fast method, evaluated on the table for each candidate.

    Keys per candidate ``name`` (``averaging``, ``fpk_fast``):
    ``{name}_third_where_lin_over_3pct`` and ``{name}_worst_ratio_where_lin_over_3pct``
    (its |error| over linearisation's, worst case), ``max_err_{name}``,
    ``{name}_within_5pct``, ``interaction_{name}_inside`` and
    ``interaction_{name}_sign_ok`` (counts), ``{name}_interaction_met``, and
    with ``timings`` (:func:`time_methods`) ``{name}_fast_enough``. The
    averaging keys keep their old short names too (``avg_...``).
    """
    lin = df["err_linearisation"].abs()
    big = lin > 0.03
    inter, width = k3_change_interval(df)
    significant = inter["dk3_mc"].abs() > width
    out = {
        "points": len(df),
        "lin_over_3pct": int(big.sum()),
        "max_err_linearisation": float(lin.max()),
        "max_err_fpk": float(df["err_fpk"].abs().max()),
        "max_mc_rel_ci95": float(df["mc_rel_ci95"].max()),
        "interaction_points": len(inter),
        "interaction_significant": int(significant.sum()),
    }
    for name in ANALYTIC:
        err = df[f"err_{name}"].abs()
        out[f"max_err_{name}"] = float(err.max())
        inside = (inter[f"dk3_{name}"] - inter["dk3_mc"]).abs() <= width
        sign_ok = ~significant | (np.sign(inter[f"dk3_{name}"]) == np.sign(inter["dk3_mc"]))
        out[f"interaction_{name}_inside"] = int(inside.sum())
        out[f"interaction_{name}_sign_ok"] = int(sign_ok.sum())
        if name == "linearisation":
            continue
        ratio = (err[big] / lin[big]).max() if big.any() else 0.0
        out[f"{name}_worst_ratio_where_lin_over_3pct"] = float(ratio)
        out[f"{name}_third_where_lin_over_3pct"] = bool(np.all(err[big] <= lin[big] / 3.0))
        out[f"{name}_within_5pct"] = bool(np.all(err <= 0.05))
        out[f"{name}_interaction_met"] = bool(inside.all() and sign_ok.all())
        if timings and f"{name}_point_s" in timings:
            out[f"{name}_fast_enough"] = bool(
                timings[f"{name}_point_s"] < POINT_BAR and timings[f"{name}_sweep100_s"] < SWEEP_BAR
            )
    out["avg_third_where_lin_over_3pct"] = out["averaging_third_where_lin_over_3pct"]
    out["avg_within_5pct"] = out["averaging_within_5pct"]
    return out


def _met(flag) -> str:
    return "**met**" if flag else "**not met**"


def criteria_table(v: dict, timings: dict) -> str:
    """The criteria for a fast method, one row each, one column per candidate (Markdown)."""
    n_int = v["interaction_points"]
    rows = []
    if timings:
        rows.append(
            ["one point < 10 ms, 100-point sweep < 1 s"]
            + [
                f"{_met(v[f'{n}_fast_enough'])}: {1e3 * timings[f'{n}_point_s']:.2f} ms, "
                f"{timings[f'{n}_sweep100_s']:.3f} s"
                for n in CANDIDATES
            ]
        )
    rows.append(
        [f"|error| <= 1/3 of linearisation's where that is > 3 % ({v['lin_over_3pct']} points)"]
        + [
            f"{_met(v[f'{n}_third_where_lin_over_3pct'])}: worst ratio "
            f"{v[f'{n}_worst_ratio_where_lin_over_3pct']:.3f}"
            for n in CANDIDATES
        ]
    )
    rows.append(
        [f"|error| <= 5 % at all {v['points']} points"]
        + [
            f"{_met(v[f'{n}_within_5pct'])}: max {100 * v[f'max_err_{n}']:.2f} %"
            for n in CANDIDATES
        ]
    )
    rows.append(
        ["k3 interaction: sign and size inside the MC interval"]
        + [
            f"{_met(v[f'{n}_interaction_met'])}: inside at {v[f'interaction_{n}_inside']} of "
            f"{n_int}, sign right at {v[f'interaction_{n}_sign_ok']} of {n_int}"
            for n in CANDIDATES
        ]
    )
    headers = ["criterion for a fast method"] + [ANALYTIC[n][1] for n in CANDIDATES]
    return markdown_table(pd.DataFrame(rows, columns=headers), floatfmt="g")


def _monotone(df: pd.DataFrame, column: str, by, along: str, sign: int) -> bool:
    """|column| strictly rising (sign = 1) or falling (-1) along ``along`` in every group."""
    groups = [g.sort_values(along)[column].abs().to_numpy() for _, g in df.groupby(by)]
    return all(np.all(sign * np.diff(g) > 0) for g in groups if len(g) > 1)


def reading(df: pd.DataFrame, timings: dict | None = None) -> str:
    """The report's reading of the table, each statement computed from it.

    Statements: the sign of linearisation's error and whether it grows with
    kappa; averaging's error as a share of linearisation's and whether it
    shrinks with k3; averaging's k3 change against the FPK reference's (sign,
    over- or understated); the largest Monte Carlo k3 change; how closely the
    fast FPK grids follow the reference, and their time per point.
    """
    fr = df[df["kappa"] > 0]
    if fr.empty:
        return "no point with friction on this grid."
    lin = fr["err_linearisation"]
    parts = ["the exact energy balance c E[z'^2] + Fc E|z'| = S m/4 means all methods differ "
             "only in E|z'|."]  # fmt: skip
    if (lin < 0).all():
        sign = "underestimates the power at every point with friction"
    elif (lin > 0).all():
        sign = "overestimates the power at every point with friction"
    else:
        sign = (
            f"underestimates the power at {int((lin < 0).sum())} of {len(lin)} points with friction"
        )
    grows = _monotone(fr, "err_linearisation", ["psd", "k3"], "kappa", 1)
    parts.append(
        f"Linearisation's Gaussian E|z'| = sqrt(2/pi) sigma_v {sign}"
        + (", increasingly with kappa" if grows else ", not monotonically in kappa")
        + " (Eq. 30 has no k3, so it predicts no k3 dependence)."
    )
    share = (fr["err_averaging"].abs() / lin.abs().where(lin.abs() > 0)).max()
    shrinks = df["k3"].nunique() > 1 and _monotone(fr, "err_averaging", ["psd", "kappa"], "k3", -1)
    parts.append(
        f"Averaging takes E|z'| from the non-Gaussian energy density: its |error| is at most "
        f"{share:.2f} times linearisation's"
        + (
            ", and shrinks as k3 raises the orbit frequency."
            if shrinks
            else ", and does not shrink steadily with k3."
        )  # fmt: skip
    )
    top = fr[fr["k3"] == df["k3"].max()]
    if df["k3"].nunique() > 1 and not top.empty:
        same_sign = bool((np.sign(top["dk3_averaging"]) == np.sign(top["dk3_fpk"])).all())
        ratio = (top["dk3_averaging"] / top["dk3_fpk"]).to_numpy()
        size = (
            f"overstates it ({ratio.min():.1f}-{ratio.max():.1f}x)"
            if (ratio > 1).all()
            else f"understates it ({ratio.min():.2f}-{ratio.max():.2f}x)"
            if (ratio < 1).all()
            else f"over- and understates it ({ratio.min():.2f}-{ratio.max():.2f}x)"
        )
        mc = top["dk3_mc"].abs().max()
        parts.append(
            f"At k3 = {df['k3'].max():g} averaging {size} relative to the FPK reference, "
            + ("with the right sign" if same_sign else "with the wrong sign at some points")
            + f"; the Monte Carlo change of power with k3 is at most {100 * mc:.2f} % there."
        )
    fast = (df["power_fpk_fast"] / df["power_fpk"] - 1).abs().max()
    speed = (
        f", at {1e3 * timings['fpk_fast_point_s']:.1f} ms a point"
        if timings and "fpk_fast_point_s" in timings
        else ""
    )
    parts.append(
        "The fast FPK method solves the same Fokker-Planck equation as the reference on small "
        "corrected grids; it follows the reference to within "
        f"{100 * fast:.3f} % at every point{speed}."
    )
    return " ".join(parts)


# ----------------------------------------------------------------- the points of a sweep
def method_errors(result, base, methods=("linearisation", "averaging")) -> pd.DataFrame:
    """A sweep's table with each method's error against Monte Carlo at every point.

    For each method m the columns of :func:`randvib.linearisation_verdicts`
    (``m_rel_error``, ``m_rel_error_ci95``, ``m_consistent``: the method
    inside the Monte Carlo 95 % interval); with averaging, also
    ``averaging_zeta_friction``, the friction damping ratio of each point's
    device (zeta_f > 0.5: outside the method's stated validity, where it warns).

    Parameters
    ----------
    result : SweepResult
        Of :func:`randvib.run_sweep` on ``base``, whose table holds each
        method's ``m_power`` (every method but the slow reference).
    base : Harvester
    methods : sequence of str
    """
    table = result.table
    for method in methods:
        table = linearisation_verdicts(table, method)
    if "averaging" in methods:
        table["averaging_zeta_friction"] = [
            float(averaging_statistics(point_device(base, p), p["psd"], warn=False).zeta_friction)
            for p in result.points
        ]
    return table


# ----------------------------------------------------------------- the cases of a paired run
def relative_error(value, reference, ci95):
    """(value / reference - 1, its 95 % half-width): a prediction against a Monte Carlo estimate.

    The half-width is the estimate's ``ci95`` propagated to first order,
    value * ci95 / reference^2.
    """
    return value / reference - 1.0, value * ci95 / reference**2


def predictions(device, excitation, methods) -> list[dict]:
    """Every method's power (W) and stroke exceedance at one case, or why it refused.

    One row per method: ``method``, ``power``, ``exceedance`` (NaN where the
    method gives none) and ``refused`` (the first clause of the refusal, ''
    where it predicted). Averaging's validity warnings are not repeated here.
    """
    rows = []
    for method in methods:
        row = {"method": method, "power": np.nan, "exceedance": np.nan, "refused": ""}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", AveragingValidityWarning)
            try:
                p = predict(device, excitation, method)
            except ValueError as err:
                # the refusal's first clause, whole (its reason); the rest is advice
                row["refused"] = str(err).split(";")[0]
                rows.append(row)
                continue
        row["power"] = float(p.power_electrical)
        if p.stroke_exceedance is not None:
            row["exceedance"] = float(p.stroke_exceedance)
        rows.append(row)
    return rows


def methods_against_monte_carlo(result, methods, *, resolved: float = 0.25) -> pd.DataFrame:
    """Every method at every case of a paired run (:class:`randvib.EnsembleResult`) against Monte Carlo.

    One row per case and method: the case's labels, the columns of
    :func:`predictions`, then ``power_rel_error`` and ``exceedance_rel_error``
    with their ``_ci95`` (:func:`relative_error`). An exceedance is compared
    only where Monte Carlo resolves it (its 95 % half-width at most
    ``resolved`` times the estimate); NaN where not compared.
    """
    rows = []
    for i, case in enumerate(result.cases):
        mc = result.table.iloc[i]
        for row in predictions(case.device, case.excitation, methods):
            row = {**case.labels, **row}
            for q, name in (("power", "power_electrical"), ("exceedance", "stroke_exceedance")):
                ref, ci = mc.get(name, np.nan), mc.get(f"{name}_ci95", np.nan)
                ok = ref > 0 and (q == "power" or ci <= resolved * ref) and np.isfinite(row[q])
                error = relative_error(row[q], ref, ci) if ok else (np.nan, np.nan)
                row[f"{q}_rel_error"], row[f"{q}_rel_error_ci95"] = error
            rows.append(row)
    return pd.DataFrame(rows)


def methods_shown(methods: pd.DataFrame, labels) -> pd.DataFrame:
    """:func:`methods_against_monte_carlo`'s table for a report: the case's ``labels``, the
    method, each error ± its half-width in % (blank where not compared) and the refusal."""
    shown = methods[[*labels, "method"]].copy()
    for q in ("power", "exceedance"):
        cells = plus_minus(methods[f"{q}_rel_error"], methods[f"{q}_rel_error_ci95"])
        shown[f"{q} error (%)"] = ["" if "nan" in c else c for c in cells]
    shown["refused"] = methods.refused.fillna("").str.slice(0, 60)
    return shown


def method_accuracy(methods: pd.DataFrame, where: str, by: str) -> dict:
    """Per method of :func:`methods_against_monte_carlo`'s table: how far from Monte Carlo, and where.

    Per method: the cases refused and in all, the negative stroke
    exceedances (a probability below zero) and the most negative one; per
    quantity (``power``, ``exceedance``; None where none was compared) the
    cases compared, the largest |error| with its half-width and where
    (``where`` formatted with that row's columns, e.g. "{device}, g = {g:g}"),
    the cases whose error is within the Monte Carlo interval, and the
    largest |error| by the values of column ``by``.
    """
    out = {}
    for method, rows in methods.groupby("method", sort=False):
        entry = {
            "refused": int((rows.refused.fillna("") != "").sum()),
            "points": int(len(rows)),
            "negative_exceedance": int((rows.exceedance < 0).sum()),
            "most_negative_exceedance": float(min(rows.exceedance.min(), 0.0))
            if rows.exceedance.notna().any() else None,
        }  # fmt: skip
        for q in ("power", "exceedance"):
            err = rows.dropna(subset=[f"{q}_rel_error"])
            if err.empty:
                entry[q] = None
                continue
            worst = err.loc[err[f"{q}_rel_error"].abs().idxmax()]
            entry[q] = {
                "compared": int(len(err)),
                "largest_abs_error": float(abs(worst[f"{q}_rel_error"])),
                "largest_ci95": float(worst[f"{q}_rel_error_ci95"]),
                "where_largest": where.format(**worst),
                "within_mc_interval": int(
                    (err[f"{q}_rel_error"].abs() <= err[f"{q}_rel_error_ci95"]).sum()
                ),
                f"largest_abs_error_by_{by}": {
                    d: float(e[f"{q}_rel_error"].abs().max()) for d, e in err.groupby(by)
                },
            }
        out[method] = entry
    return out


def accuracy_sentences(accuracy: dict, by: str) -> list[str]:
    """A Markdown bullet per method of :func:`method_accuracy`'s summary, in words."""
    lines = []
    for method, e in accuracy.items():
        text = [f"**{method}**: refused at {e['refused']} of {e['points']} points"]
        if e["negative_exceedance"]:
            text.append(
                f"a negative stroke exceedance (a probability below zero) at "
                f"{e['negative_exceedance']} points, down to {e['most_negative_exceedance']:.2g}"
            )
        for q in ("power", "exceedance"):
            a = e[q]
            if a is None:
                text.append(f"no {q} compared")
                continue
            by_value = ", ".join(
                f"{d} {100 * x:.2g} %" for d, x in a[f"largest_abs_error_by_{by}"].items()
            )
            text.append(
                f"{q}: largest |error| {100 * a['largest_abs_error']:.3g} % (± "
                f"{100 * a['largest_ci95']:.2g} %, {a['where_largest']}) over {a['compared']} "
                f"points, {a['within_mc_interval']} within the Monte Carlo interval; "
                f"by {by}: {by_value}"
            )
        lines.append("- " + "; ".join(text) + ".")
    return lines


def linearisation_against_monte_carlo(result) -> pd.DataFrame:
    """Statistical linearisation at every case of a paired run, against its Monte Carlo power.

    Columns ``power_linearisation`` (W), ``k_eq`` (N/m), ``c_eq`` (Ns/m)
    (:func:`randvib.statistical_linearisation`: any input, Gaussian closure)
    and ``linearisation_rel_error`` with its ``_ci95`` (:func:`relative_error`),
    indexed like the run's table.
    """
    rows = []
    for i, case in enumerate(result.cases):
        sl = statistical_linearisation(case.device, case.excitation)
        mc = result.table.iloc[i]
        error = relative_error(sl.power_electrical, mc.power_electrical, mc.power_electrical_ci95)
        rows.append({
            "power_linearisation": sl.power_electrical, "k_eq": sl.k_eq, "c_eq": sl.c_eq,
            "linearisation_rel_error": error[0], "linearisation_rel_error_ci95": error[1],
        })  # fmt: skip
    return pd.DataFrame(rows, index=result.table.index)
