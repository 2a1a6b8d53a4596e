"""Verdicts in words: the sentences of the studies' reports, built from the numbers.

Each function takes a study's result table and returns the numbers behind
the verdict (for ``verdicts.json``) and/or the sentence of the report, so
that the wording always follows the data (the tests check both on synthetic
tables).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from randvib.formatting import plus_minus
from randvib.studies.evidence import rescaling_groups
from randvib.studies.report import fc_levels, sign_word


def linearisation_verdict(table: pd.DataFrame) -> tuple[dict, str]:
    """Eq. 32 against Monte Carlo: the numbers behind the verdict, and the sentence.

    A point is *outside* where Eq. 32 is outside the Monte Carlo 95 % interval
    (``linearisation_consistent`` False). Its sign is the sign of
    ``linearisation_rel_error`` (negative: Eq. 32 under-predicts). "Higher
    friction" means the upper half of the Fc range of the point's (S, k3)
    series (Fc / max Fc > 1/2). Friction-free points are exact (control
    variates) and are not counted among the points that could be outside by
    chance.
    """
    fc_max = table.groupby(["psd", "k3"]).fc.transform("max")
    rel_level = table.fc / fc_max
    outside = table[~table.linearisation_consistent.astype(bool)]
    n_friction = int((table.fc > 0).sum())
    groups = pd.Series(rescaling_groups(table), index=table.index)
    n_independent_friction = groups[table.fc > 0].nunique()
    under = int((outside.linearisation_rel_error < 0).sum())
    over = int((outside.linearisation_rel_error > 0).sum())
    high = int((rel_level[outside.index] > 0.5).sum())
    data = {
        "n_points": len(table),
        "n_friction_points": n_friction,
        "n_outside": len(outside),
        "n_independent_points": int(groups.nunique()),
        "n_independent_friction_points": int(n_independent_friction),
        "n_outside_independent": int(groups[outside.index].nunique()),
        "expected_by_chance": 0.05 * n_independent_friction,
        "n_under": under,
        "n_over": over,
        "n_outside_high_friction": high,
        "outside_points": outside[["psd", "k3", "fc"]].to_dict("records"),
    }
    chance = f"{data['expected_by_chance']:.1f} expected by chance at 95 %"
    if outside.empty:
        sentence = (
            "Eq. 32 lies inside the Monte Carlo 95 % interval at every point: at the resolution "
            "of these intervals it is not distinguishable from the simulated power."
        )
    else:
        if high == len(outside):
            where = "all of them in the upper half of their series' friction range"
        elif high == 0:
            where = "none of them in the upper half of their series' friction range"
        else:
            where = f"{high} of them in the upper half of their series' friction range"
        if over == 0:
            sign = "Eq. 32 under-predicts the power at every one"
        elif under == 0:
            sign = "Eq. 32 over-predicts the power at every one"
        else:
            sign = f"Eq. 32 under-predicts at {under} and over-predicts at {over}"
        levels = (
            "every point with friction"
            if len(outside) == n_friction and (outside.fc > 0).all()
            else fc_levels(outside)
        )
        if n_independent_friction == n_friction:
            among = f"{chance} among the {n_friction} with friction"
        else:
            among = (
                f"{data['n_outside_independent']} of the {n_independent_friction} independent "
                f"points with friction, {chance}: the k3 = 0 rows at different S are exact "
                "rescalings of the same noise paths and count once"
            )
        sentence = (
            f"Eq. 32 is outside the Monte Carlo 95 % interval at {len(outside)} of {len(table)} "
            f"points ({among}), {where} ({levels}); {sign}."
        )
        if over == 0 and len(outside) > data["expected_by_chance"]:
            sentence += (
                " An under-prediction means a simulated E|z'| below the Gaussian "
                "sqrt(2/pi) sigma_v (exact energy balance): the velocity is not Gaussian "
                "once the magnet sticks."
            )
    return data, sentence


def interaction_verdict(inter: pd.DataFrame, k3: float) -> tuple[dict, str]:
    """The verdict on the contrasts at one spring ``k3`` (N/m^3): counts, the largest, the sentence.

    ``inter`` is the table of :func:`randvib.studies.contrasts.interaction_contrasts`
    (at least ``psd``, ``fc``, ``relative_contrast``, ``relative_ci95``,
    ``detectable``, ``detectable_holm``).
    """
    big = inter.loc[inter.relative_contrast.abs().idxmax()]
    holm = inter[inter.detectable_holm.astype(bool)]
    data = {
        "n_contrasts": len(inter),
        "n_detectable": int(inter.detectable.sum()),
        "n_holm": len(holm),
        "largest_relative_contrast": float(big.relative_contrast),
        "largest_relative_ci95": float(big.relative_ci95),
        "largest_at": {"psd": float(big.psd), "fc": float(big.fc)},
        "bound_relative": float((inter.relative_contrast.abs() + inter.relative_ci95).max()),
    }
    if holm.empty:
        sentence = (
            f"no interaction is detectable at this precision (0 of {len(inter)} contrasts after "
            f"Holm's correction); the contrast stays within ±{100 * data['bound_relative']:.2f} % "
            "of P(Fc, 0) (largest |estimate| + 95 % half-width)."
        )
    else:
        sign = sign_word(holm)
        sentence = (
            f"an interaction is detectable at {len(holm)} of {len(inter)} (S, Fc) points after "
            f"Holm's correction ({fc_levels(holm.assign(k3=k3))}), {sign}, up to "
            f"{100 * holm.relative_contrast.abs().max():.2f} % of P(Fc, 0): the Duffing spring "
            "changes the friction-affected power, which Eq. 32 cannot show."
        )
    return data, sentence


def growth_words(inter: pd.DataFrame, column: str = "averaging_relative_contrast") -> str:
    """' growing in size with k3 and Fc' where |column| rises along both axes, else what holds."""

    def rising(by: str, along: str) -> bool:
        return all(
            bool(np.all(np.diff(sub.sort_values(along)[column].abs().to_numpy()) > 0))
            for _, sub in inter.groupby(["psd", by])
            if len(sub) > 1
        )

    with_fc, with_k3 = rising("k3", "fc"), rising("fc", "k3")
    if with_fc and with_k3:
        return " growing in size with k3 and Fc"
    if with_fc:
        return " growing in size with Fc (not monotonically with k3)"
    if with_k3:
        return " growing in size with k3 (not monotonically with Fc)"
    return " (not monotonic in k3 or Fc)"


def interaction_counts(inter: pd.DataFrame, k3s) -> dict:
    """The numbers behind the interaction verdict, per k3 (keys are k3 as text)."""
    out = {"n_contrasts": len(inter), "n_holm": int(inter.detectable_holm.sum()), "by_k3": {}}
    for k3 in k3s:
        if k3 == 0:
            continue
        sub = inter[inter.k3 == k3]
        worst = sub.loc[sub.relative_contrast.abs().idxmax()]
        out["by_k3"][f"{k3:g}"] = {
            "n": len(sub),
            "n_detectable": int(sub.detectable.sum()),
            "n_holm": int(sub.detectable_holm.sum()),
            "largest_relative_contrast": float(worst.relative_contrast),
            "largest_relative_ci95": float(worst.relative_ci95),
            "bound_relative": float((sub.relative_contrast.abs() + sub.relative_ci95).max()),
        }
    return out


def summary_by_spring(inter: pd.DataFrame, k3s, labels: dict) -> pd.DataFrame:
    """One row per k3 > 0: detectable counts, the largest contrast, its bound (report table)."""
    rows = []
    for k3 in k3s:
        if k3 == 0:
            continue
        sub = inter[inter.k3 == k3]
        worst = sub.loc[sub.relative_contrast.abs().idxmax()]
        bound = (sub.relative_contrast.abs() + sub.relative_ci95).max()
        rows.append(
            {
                "k3 (N/m^3)": f"{k3:.3g}" + (f" ({labels[k3]})" if k3 in labels else ""),
                "detectable (95 %, per point)": f"{int(sub.detectable.sum())} of {len(sub)}",
                "detectable (Holm)": f"{int(sub.detectable_holm.sum())} of {len(sub)}",
                "largest contrast (%)": plus_minus(
                    worst.relative_contrast, worst.relative_ci95, fmt="+.3f"
                )[0],
                "at S, phi": f"{worst.psd:g}, {worst.phi:.2f}",
                "bound on |contrast| (%)": f"{100 * bound:.3f}",
                "averaging, largest (%)": f"{100 * sub.averaging_relative_contrast.abs().max():.3f}"
                if "averaging_relative_contrast" in sub
                else "n/a",
            }
        )
    return pd.DataFrame(rows)


def interaction_summary(
    inter: pd.DataFrame, k3s, labels: dict | None = None
) -> tuple[str, pd.DataFrame]:
    """The verdict sentence on the contrasts over several springs, and a per-k3 summary table.

    ``inter`` as for :func:`interaction_verdict`, with ``k3`` and ``phi``
    columns (and ``averaging_relative_contrast`` when averaging is compared);
    ``labels`` names some k3 values (e.g. {5e5: "Fig. 9"}).
    """
    labels = labels or {}
    summary = summary_by_spring(inter, k3s, labels)
    holm = inter[inter.detectable_holm]
    top = max(k for k in k3s)
    at_top = inter[inter.k3 == top]
    label = f" ({labels[top]})" if top in labels else ""
    if holm.empty:
        bound = 100 * (at_top.relative_contrast.abs() + at_top.relative_ci95).max()
        verdict = (
            f"No interaction is detectable at the family level (Holm, 5 %, {len(inter)} "
            f"contrasts). Even at k3 = {top:.3g} N/m^3{label} the contrast stays within "
            f"±{bound:.2f} % of P(Fc, 0) (largest |estimate| + 95 % half-width)."
        )
        single = at_top[at_top.detectable]
        if len(single):
            verdict += (
                f" There, {len(single)} of {len(at_top)} contrasts pass on their own "
                f"(95 %, uncorrected; {0.05 * len(at_top):.1f} expected by chance), "
                + sign_word(single)
                + f", up to {100 * single.relative_contrast.abs().max():.2f} %: a hint of an "
                f"interaction below {bound:.2f} %, not established at this precision."
            )
    else:
        where = holm.groupby("k3").size()
        big = holm.loc[holm.relative_contrast.abs().idxmax()]
        verdict = (
            f"The interaction is detectable (Holm, family level 5 %) at {len(holm)} of "
            f"{len(inter)} (S, Fc, k3) points: "
            + ", ".join(f"{n} at k3 = {k:.3g}" for k, n in where.items())
            + f". The largest is {100 * big.relative_contrast:+.2f} % ± "
            f"{100 * big.relative_ci95:.2f} % of P(Fc, 0) (k3 = {big.k3:.3g} N/m^3, "
            f"S = {big.psd:g}, Fc = {1e3 * big.fc:.3g} mN, phi = {big.phi:.2f})."
        )
        if top in where.index:
            share = at_top[at_top.detectable_holm]
            size = (
                f"{100 * share.relative_contrast.iloc[0]:+.2f} %"
                if len(share) == 1
                else sign_word(share) + f", {100 * share.relative_contrast.abs().min():.2f} % to "
                f"{100 * share.relative_contrast.abs().max():.2f} % in magnitude"
            )
            verdict += (
                f" At k3 = {top:.3g} N/m^3{label}: {len(share)} of {len(at_top)} points, "
                f"{size} (of P(Fc, 0))."
            )
    if "averaging_relative_contrast" in inter:
        miss = (inter.averaging_relative_contrast - inter.relative_contrast).abs() > (
            inter.relative_ci95
        )
        verdict += (
            f" Stochastic averaging predicts {sign_word(inter[inter.averaging_relative_contrast.abs() > 1e-4], 'averaging_relative_contrast')} "
            f"contrasts{growth_words(inter)}, up to "
            f"{100 * inter.averaging_relative_contrast.abs().max():.2f} %; the Monte Carlo 95 % "
            f"interval excludes its prediction at {int(miss.sum())} of {len(inter)} points"
            + (
                f" (k3 = {', '.join(f'{k:.3g}' for k in sorted(inter[miss].k3.unique()))})."
                if miss.any()
                else "."
            )
        )
    return verdict, summary


def linearisation_by_spring(lin: pd.DataFrame) -> dict:
    """Where Eq. 32's error is largest, and how much it changes with k3 at equal (S, Fc).

    ``spread`` is the largest range over k3 of the error at one (S, Fc);
    ``spread_ci95`` the largest 95 % half-width among the points; the
    sentence says whether the spring changes the error by more than the
    combined interval sqrt(2) * spread_ci95.
    """
    top_fc = lin.groupby(["psd", "k3"]).fc.transform("max")
    idx = lin.groupby(["psd", "k3"]).linearisation_rel_error.apply(lambda e: e.abs().idxmax())
    at_top = int((lin.loc[idx, "fc"] == top_fc.loc[idx]).sum())
    if at_top == len(idx):
        where = (
            "the largest |error| of every (S, k3) series is at its highest Fc, "
            f"phi = {lin.phi.max():.2f}"
        )
    else:
        where = f"largest at the highest Fc in {at_top} of {len(idx)} (S, k3) series"
    by_point = lin.groupby(["psd", "fc"])
    spread = float(by_point.linearisation_rel_error.agg(lambda e: e.max() - e.min()).max())
    half = float(lin.linearisation_rel_error_ci95.max())
    if by_point.k3.nunique().max() < 2:
        sentence = "No (S, Fc) has more than one k3 here, so the spring's effect is not resolved."
    elif spread <= np.sqrt(2) * half:
        sentence = (
            f"At equal S and Fc it changes with k3 by at most {100 * spread:.2f} %, within the "
            f"combined intervals (sqrt(2) x the 95 % half-widths, up to {100 * half:.2f} %): it "
            "is set by the friction level, with no resolved dependence on the spring - the "
            "interaction verdict above seen from the other side."
        )
    else:
        sentence = (
            f"At equal S and Fc it changes with k3 by up to {100 * spread:.2f} %, more than the "
            f"combined intervals (sqrt(2) x the 95 % half-widths, up to {100 * half:.2f} %): "
            "the spring changes Eq. 32's error."
        )
    return {
        "series_largest_at_top_fc": at_top,
        "n_series": len(idx),
        "where_largest": where,
        "spread": spread,
        "spread_ci95": half,
        "sentence": sentence,
    }


def scaling_sentence(inter: pd.DataFrame) -> str:
    """How closely rows with equal (phi, mu) agree (exact scaling: to rounding)."""
    key = [inter.phi.round(9), inter.mu.round(9)]
    groups = [g for _, g in inter.groupby(key) if len(g) > 1]
    if not groups:
        return "; no two rows of this grid share (phi, mu)."
    diff = max(float(g.relative_contrast.max() - g.relative_contrast.min()) for g in groups)
    if diff <= 1e-9:
        return (
            f"; the {len(groups)} such groups here agree to {diff:.1e} of P(Fc, 0), i.e. to "
            "rounding - a check of the simulator, not extra evidence."
        )
    return (
        f"; the {len(groups)} such groups here differ by up to {100 * diff:.3g} % of P(Fc, 0), "
        "more than rounding: the exact scaling does not hold in these results."
    )


def contrast_range(sub: pd.DataFrame, where: str = "{centre}, zeta = {zeta:g}") -> dict:
    """The contrasts of one family in numbers: breaks, range, the smallest in magnitude.

    ``sub`` holds ``relative_contrast``, ``relative_ci95`` and
    ``breaks_no_interaction`` (detectable after Holm and practically large);
    ``where`` names the smallest's row (formatted with its columns).
    """
    small = sub.loc[sub.relative_contrast.abs().idxmin()]
    return {"n_breaks": int(sub.breaks_no_interaction.sum()), "n_points": int(len(sub)),
            "min_relative_contrast": float(sub.relative_contrast.min()),
            "max_relative_contrast": float(sub.relative_contrast.max()),
            "smallest_abs": float(small.relative_contrast),
            "smallest_abs_ci95": float(small.relative_ci95),
            "smallest_abs_where": where.format(**small)}  # fmt: skip


def holds_down_to(sub: pd.DataFrame, along: str = "zeta") -> float | None:
    """The smallest value of ``along``, from the largest down, before the first row that
    ``breaks_no_interaction``; None when the first one already breaks it (e.g. the
    narrowest band down to which no interaction holds, from the broadest)."""
    ordered = sub.sort_values(along, ascending=False)
    breaks = ordered.breaks_no_interaction.to_numpy(dtype=bool)
    held = len(breaks) if not breaks.any() else int(np.argmax(breaks))
    return float(ordered[along].iloc[held - 1]) if held else None
