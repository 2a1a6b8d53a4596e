"""Adversarial cross-check of the analytic methods against Monte Carlo (run by hand).

python tests/calibration/crosscheck.py [--focus NAME] [n_cases] [out.jsonl] [first_case]

Samples devices with seeded numpy draws (case i from ``default_rng(2600 + i)``):
Duffing k3 from 0 to very hard, double wells shallow to deep, Coulomb / tanh
/ LuGre friction from none to near-sticking (the Coulomb force over the
viscous force at the friction-free velocity std, 0.03 to 30), light to heavy
damping, white noise and the rational excitations, resistive, coil and piezo
couplings. Every method of ``randvib.METHODS`` that takes the case is asked;
its status is "answered" (no warning), "warned" or "refused". The reference
is exact where it is known (no friction, white noise, resistive coupling:
E[P_e] = c_e S m / (4 c), the Gibbs density) and Monte Carlo otherwise
(control variates under white noise; ensembles sized until the 95 %
interval is <= 3 % of the power, the step from the linearised device's
variance bias <= 0.2 %). A silent failure is an answer without a warning
further than 10 % + the reference's 95 % interval from it.

Each case is one JSON line of ``out.jsonl`` (parameters, indicators,
reference and every method's status and answer); the summary table (failures
by method and regime, and the fraction answered silently) is printed at the end
and by ``python tests/calibration/crosscheck.py --summary out.jsonl``.
"""

from __future__ import annotations

import json
import sys
import time
import warnings
from collections import Counter, defaultdict

import numpy as np

import randvib as rv
from randvib.montecarlo.step_check import largest_step

M = 0.0226  # kg, the conventions' magnet mass
#: Relative error beyond which an answer must warn or refuse (issue bar).
BAR = 0.10
#: Largest acceptable 95 % half-width of the Monte Carlo reference, relative.
MC_TARGET = 0.03


#: Focused campaigns: what a case is forced to be (``--focus NAME``), for the
#: regimes the broad campaign found failures in; their cases draw from seeds
#: 9000 + i so they never repeat the broad campaign's.
FOCUS = {
    "bistable-friction": {"potential": "bistable", "friction": ("coulomb", "tanh"), "white": True},
    "circuit": {"coupling": ("coil", "piezo")},
    "coloured": {"white": False},
}


def draw(i: int, focus: str | None = None) -> dict:
    """Case ``i``'s parameters (a dict of plain floats and strings)."""
    forced = FOCUS[focus] if focus else {}
    g = np.random.default_rng((9000 if focus else 2600) + i)
    case = {"case": i, "m": M}
    c_m, c_e = 10.0 ** g.uniform(-3.3, -0.7, 2)
    case.update(c_m=float(c_m), c_e=float(c_e))
    s = float(10.0 ** g.uniform(-3, 0))
    case["S"] = s
    c = c_m + c_e
    var_v0 = s * M / (4 * c)  # friction-free E[v^2]
    u = g.uniform()
    if forced.get("potential") == "bistable":
        u = 0.55 + 0.45 * u
    if u < 0.55:
        case["regime_potential"] = "duffing"
        case["k"] = float(57.4 * 10 ** g.uniform(-0.5, 0.5))
        hard = g.uniform()
        # k3 from 0 to "very hard": 3 k3 E[z^2]/k from 0 to 1e4 (E[z^2] ~ var_v0 m / k)
        if hard < 0.2:
            case["k3"] = 0.0
        else:
            ratio = 10 ** g.uniform(-2, 4)
            z2 = var_v0 * M / case["k"]
            case["k3"] = float(ratio * case["k"] / (3 * z2))
        if g.uniform() < 0.05:
            case["k3"] = float(10 ** g.uniform(20, 120))  # absurdly hard
            case["regime_potential"] = "duffing-extreme"
    else:
        case["regime_potential"] = "bistable"
        k = -57.4 * 10 ** g.uniform(-0.5, 0.5)
        depth = 10 ** g.uniform(-1, 1.6)  # barrier over m E[v^2]
        case["k"] = float(k)
        case["k3"] = float(k * k / (4 * depth * M * var_v0))
        case["depth"] = float(depth)
    f = g.uniform()
    if forced.get("friction"):
        f = 0.25 + 0.6 * f  # Coulomb or tanh
    r = float(10 ** g.uniform(-1.5, 1.5))  # Fc over c sigma_v0
    fc = r * c * np.sqrt(var_v0)
    if f < 0.25:
        case["friction"] = "none"
    elif f < 0.6:
        case.update(friction="coulomb", fc=float(fc))
    elif f < 0.85:
        case.update(
            friction="tanh", fc=float(fc), beta=float(10 ** g.uniform(0, 3) / np.sqrt(var_v0))
        )
    else:
        case.update(friction="lugre", fc=float(fc))
    case["fc_ratio"] = r if case["friction"] != "none" else 0.0
    e = g.uniform()
    if "white" in forced:
        e = 0.0 if forced["white"] else 0.75 + 0.25 * e
    if e < 0.75:
        case["excitation"] = "white"
    else:
        case["excitation"] = "bandpass" if e < 0.87 else "kanai-tajimi"
        case["f0"] = float(g.uniform(4, 20))
        case["zeta"] = float(10 ** g.uniform(-1.3, -0.3))
    cp = g.uniform()
    if forced.get("coupling"):
        cp = 0.7 + 0.3 * cp
    elif forced.get("potential"):
        cp = 0.0  # resistive: the FPK methods take it
    if cp < 0.7:
        case["coupling"] = "resistive"
    elif cp < 0.85:
        case["coupling"] = "coil"
        case["r_coil"] = 0.48
        case["r_load"] = float(10 ** g.uniform(-0.5, 1.0))
        case["alpha"] = float(np.sqrt(c_e * (case["r_load"] + 0.48)))
        case["inductance"] = float(10 ** g.uniform(-4, -1))
    else:
        case["coupling"] = "piezo"
        case["capacitance"] = 5e-8
        case["r_load"] = float(1 / (2 * np.pi * 8 * 5e-8) * 10 ** g.uniform(-1, 1))
        case["theta"] = float(np.sqrt(c_e / case["r_load"]))
    return case


def build(case: dict):
    """(harvester, psd) of a case."""
    friction = {
        "none": lambda: None,
        "coulomb": lambda: rv.Coulomb(case["fc"]),
        "tanh": lambda: rv.Tanh(case["fc"], case["beta"]),
        "lugre": lambda: rv.LuGre(2.0, 0.18, case["fc"], 1.4 * case["fc"], 0.007),
    }[case["friction"]]()
    common = dict(m=case["m"], c_m=case["c_m"], k=case["k"], k3=case["k3"], friction=friction)
    if case["coupling"] == "resistive":
        h = rv.Harvester(c_e=case["c_e"], **common)
    elif case["coupling"] == "coil":
        coupling = rv.Inductive(case["alpha"], case["r_load"], case["r_coil"], case["inductance"])
        h = rv.Harvester.with_coupling(coupling=coupling, **common)
    else:
        coupling = rv.Piezo(case["theta"], case["capacitance"], case["r_load"])
        h = rv.Harvester.with_coupling(coupling=coupling, **common)
    if case["excitation"] == "white":
        psd = case["S"]
    elif case["excitation"] == "bandpass":
        psd = rv.BandPass(case["S"], case["f0"], case["zeta"])
    else:
        psd = rv.KanaiTajimi(case["S"], case["f0"], case["zeta"])
    return h, psd


def ask(h, psd, name: str) -> dict:
    """One method's status ("answered", "warned", "refused", "declines") and answer."""
    method = rv.METHODS[name]
    if not method.accepts(h, psd):
        return {"status": "declines"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            p = float(rv.predict(h, psd, name).power_electrical)
        except ValueError as exc:
            return {"status": "refused", "why": str(exc)[:160]}
    own = [w for w in caught if issubclass(w.category, Warning) and "randvib" in w.filename]
    ours = [w for w in caught if type(w.message).__module__.startswith("randvib")]
    if ours or own:
        text = str((ours or own)[0].message)[:160]
        return {"status": "warned", "power": p, "why": text}
    return {"status": "answered", "power": p}


def reference(case: dict, h, psd) -> dict:
    """Exact power where known, else Monte Carlo with its 95 % half-width."""
    if (
        case["friction"] == "none"
        and case["excitation"] == "white"
        and case["coupling"] == "resistive"
    ):
        c = case["c_m"] + case["c_e"]
        return {"ref": case["c_e"] * case["S"] * case["m"] / (4 * c), "ci95": 0.0, "kind": "exact"}
    if case["regime_potential"] == "duffing-extreme":
        return {"kind": "none", "why": "k3 beyond Monte Carlo's reach"}
    white = case["excitation"] == "white"
    try:
        dt = largest_step("heun", h, psd, bias=0.002)
    except Exception as exc:  # noqa: BLE001 - recorded, the case is skipped
        return {"kind": "none", "why": f"step: {exc}"[:160]}
    dt = min(dt, 2e-3)
    if case["coupling"] == "coil":
        # the step check's variance bias can accept a step near the circuit's
        # time constant L / R, where the coil's current is not resolved
        dt = min(dt, 0.2 * case["inductance"] / (case["r_load"] + case["r_coil"]))
    c_eff = case["c_m"] + case["c_e"]
    relax = M / c_eff  # energy relaxation time without friction (s), an upper bound with it
    burn = float(min(max(3 * relax, 2.0), 150.0))
    t_end = burn + float(min(max(10 * relax, 20.0), 300.0))
    n_steps = t_end / dt
    if n_steps > 4e6:
        return {"kind": "none", "why": f"too costly: dt {dt:.2g} s, t_end {t_end:.3g} s"}
    n_paths = 32
    for _ in range(3):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = rv.simulate(
                    h,
                    psd,
                    t_end=t_end,
                    dt=dt,
                    n_paths=n_paths,
                    burn_in=burn,
                    seed=case["case"],
                    control_variates=white,
                    progress=False,
                    threads=1,
                )
        except ValueError as exc:
            return {"kind": "none", "why": f"simulate: {exc}"[:200]}
        p = r.power_electrical
        if p.relative_ci95 <= MC_TARGET or n_paths * n_steps > 4e7:
            break
        n_paths = int(min(n_paths * max(2, (p.relative_ci95 / MC_TARGET) ** 2 * 1.2), 512))
    return {
        "ref": p.mean,
        "ci95": p.ci95,
        "kind": "mc",
        "n_paths": n_paths,
        "dt": dt,
        "t_end": t_end,
        "friction_power": r.friction_power.mean,
        "v2": r.velocity_variance.mean,
        "abs_v": r.mean_abs_velocity.mean,
    }


def run_case(i: int, focus: str | None = None) -> dict:
    case = draw(i, focus)
    h, psd = build(case)
    t0 = time.time()
    out = dict(case)
    out["methods"] = {name: ask(h, psd, name) for name in rv.METHODS if name != "bridge-closure"}
    out.update(reference(case, h, psd))
    out["seconds"] = round(time.time() - t0, 2)
    return out


def verdicts(row: dict) -> dict:
    """Per method: "silent-fail", "ok", "warned-fail", "warned-ok", "refused", "declines", "no-ref"."""
    res = {}
    for name, m in row["methods"].items():
        st = m["status"]
        if st in ("refused", "declines"):
            res[name] = st
            continue
        if row.get("kind") in (None, "none") or not row.get("ref"):
            res[name] = "no-ref"
            continue
        err = abs(m["power"] - row["ref"]) - BAR * abs(row["ref"]) - row["ci95"]
        bad = err > 0
        res[name] = (
            ("silent-fail" if bad else "ok")
            if st == "answered"
            else ("warned-fail" if bad else "warned-ok")
        )
    return res


def regime(row: dict) -> str:
    ex = "white" if row["excitation"] == "white" else "coloured"
    return f"{row['regime_potential']}/{row['friction']}/{ex}/{row['coupling']}"


def summary(rows: list[dict]) -> None:
    table = defaultdict(Counter)
    fails = defaultdict(Counter)
    for row in rows:
        for name, v in verdicts(row).items():
            table[name][v] += 1
            if v == "silent-fail":
                fails[name][regime(row)] += 1
    print(f"\n{len(rows)} cases")
    for name, counts in table.items():
        asked = sum(n for v, n in counts.items() if v != "declines")
        silent = counts["ok"] + counts["silent-fail"]
        print(f"{name:14s} {dict(counts)}  answered-silently {silent}/{asked}")
    print("\nsilent failures by method and regime:")
    for name, counts in fails.items():
        for reg, n in counts.most_common():
            print(f"  {name:14s} {reg:45s} {n}")
    print("\nworst silent failures:")
    worst = []
    for row in rows:
        for name, v in verdicts(row).items():
            if v == "silent-fail":
                ratio = row["methods"][name]["power"] / row["ref"]
                worst.append((abs(ratio - 1), name, row["case"], ratio, regime(row)))
    for _err, name, i, ratio, reg in sorted(worst, reverse=True)[:40]:
        print(f"  case {i:4d} {name:14s} ratio {ratio:.3f}  {reg}")


def main(argv: list[str]) -> None:
    if argv and argv[0] == "--summary":
        rows = [json.loads(line) for line in open(argv[1])]
        summary(rows)
        return
    focus = None
    if argv and argv[0] == "--focus":
        focus, argv = argv[1], argv[2:]
    n = int(argv[0]) if argv else 200
    path = argv[1] if len(argv) > 1 else "crosscheck.jsonl"
    first = int(argv[2]) if len(argv) > 2 else 0
    rows = []
    with open(path, "a") as out:
        for i in range(first, first + n):
            try:
                row = run_case(i, focus)
            except Exception as exc:  # noqa: BLE001 - a case that breaks the harness is recorded
                row = {"case": i, "harness_error": repr(exc)[:300], "methods": {}}
            rows.append(row)
            out.write(json.dumps(row) + "\n")
            out.flush()
            print(i, row.get("seconds"), regime(row) if "excitation" in row else row, flush=True)
    summary([r for r in rows if "harness_error" not in r])


if __name__ == "__main__":
    main(sys.argv[1:])
