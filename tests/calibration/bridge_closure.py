"""The bridge's Gaussian closure (method='bridge-closure') against Monte Carlo, over a grid.

Run by hand (not collected by pytest), from the repository root::

    python tests/calibration/bridge_closure.py            # white noise
    python tests/calibration/bridge_closure.py coloured   # rational spectra
    python tests/calibration/bridge_closure.py capacitor  # storage capacitor's R_L, R_L C

Grid: the paper's device (m 0.0226 kg, c_m 0.05 Ns/m, k 57.4 N/m, k3 5e4 N/m^3)
and coil (alpha 0.1992 Wb/m, R_C 0.48 ohm), S in {0.25, 1} (m/s^2)^2/Hz, no
friction or Coulomb Fc = 0.005 N, V_d in {0, 0.02} V, and a battery V_b in
{0, 0.02, 0.05, 0.1} V or a storage capacitor (R_L 2 ohm, C 0.5 F: R_L C = 1 s,
eight periods). Monte Carlo: 64 paths x 10 s after a burn-in of 5 s
(3 R_L C + 2 s with the capacitor), dt 2e-4 s, control variates. Prints, per
point, u0/sigma_v (the declared validity indicator), the closure's stored
power, Monte Carlo's with its 95 % half-width, and the relative error; then the
largest |error| with u0/sigma_v <= the declared limit. The numbers are quoted
in docs/conventions.md ("Rectified circuits").

Coloured grid (``coloured``): the same device and coil with V_d 0.01 V, band-pass
BandPass(S, 8 Hz, zeta) at (S, zeta) = (1, 0.3), (0.25, 0.3), (1, 0.1) and
Kanai-Tajimi KanaiTajimi(0.25, 8 Hz, 0.3) and the paper's flat band
BandLimited(1, 4 Hz, 20 Hz) (spectral integral, not rational), no friction or Coulomb Fc = 0.005 N, a
battery V_b in {0.02, 0.05} V or the storage capacitor above; Monte Carlo 128
paths x 8 s after a burn-in of 4 s, dt 2e-4 s (control variates for the rational
spectra; the flat band is synthesised, without them).

Capacitor grid (``capacitor``): white noise S in {0.25, 1}, no friction or Coulomb
Fc = 0.005 N, V_d 0.01 V, R_L in {0.5, 2, 8} ohm (R_L / R_C 1.04, 4.2, 16.7) and
R_L C in {1, 2, 4, 8} natural periods; Monte Carlo 64 paths x 10 s after a
burn-in of 3 R_L C + 2 s, dt 2e-4 s. The largest |error| is printed over the
points the closure offers (u0/sigma_v <= 1.25, R_L C >= 4 periods, R_L >= 4 R_C).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT)]

import numpy as np  # noqa: E402

import randvib as rv  # noqa: E402
from randvib.analytic.bridge import MAX_THRESHOLD_RATIO  # noqa: E402

M, C_M, K, K3 = 0.0226, 0.05, 57.4, 5e4
ALPHA, R_COIL = 0.1992, 0.48


def main() -> None:
    warnings.simplefilter("ignore")
    if sys.argv[1:2] == ["coloured"]:
        coloured()
        return
    if sys.argv[1:] == ["capacitor"]:
        capacitor()
        return
    rows = []
    for psd in (0.25, 1.0):
        for fc in (0.0, 0.005):
            for v_d in (0.0, 0.02):
                outputs = [dict(battery=v) for v in (0.0, 0.02, 0.05, 0.1)]
                outputs.append(dict(storage_capacitance=0.5, r_load=2.0))
                for out in outputs:
                    coil = rv.BridgeCoil(ALPHA, R_COIL, v_diode=v_d, **out)
                    friction = rv.Coulomb(fc) if fc > 0 else None
                    h = rv.Harvester.with_coupling(M, C_M, K, coil, k3=K3, friction=friction)
                    label = f"S {psd:<5g} Fc {fc:<6g} V_d {v_d:<5g} {coil.output_words:<34}"
                    rows.append(_compare(h, psd, label, burn_in=5.0, t_end=15.0, n_paths=64))
    inside = [abs(e) for r, e in rows if r <= MAX_THRESHOLD_RATIO and np.isfinite(e)]
    print(f"largest |error| with u0/sigma_v <= {MAX_THRESHOLD_RATIO:g}: {max(inside):.2%}")


def coloured() -> None:
    rows = []
    spectra = (
        rv.BandPass(1.0, 8.0, 0.3), rv.BandPass(0.25, 8.0, 0.3), rv.BandPass(1.0, 8.0, 0.1),
        rv.KanaiTajimi(0.25, 8.0, 0.3), rv.BandLimited(1.0, 4.0, 20.0),
    )  # fmt: skip
    only = sys.argv[2:]  # e.g. "BandLimited": that spectrum alone
    for psd in spectra:
        if only and type(psd).__name__ not in only:
            continue
        for fc in (0.0, 0.005):
            outputs = [dict(battery=0.02), dict(battery=0.05)]
            outputs.append(dict(storage_capacitance=0.5, r_load=2.0))
            for out in outputs:
                coil = rv.BridgeCoil(ALPHA, R_COIL, v_diode=0.01, **out)
                friction = rv.Coulomb(fc) if fc > 0 else None
                h = rv.Harvester.with_coupling(M, C_M, K, coil, k3=K3, friction=friction)
                label = f"{psd!r:<40} Fc {fc:<6g} {coil.output_words:<34}"
                rows.append(
                    _compare(h, psd, label, burn_in=4.0, t_end=12.0, n_paths=128,
                             control_variates=psd.shaping_filter() is not None)
                )  # fmt: skip
    inside = [abs(e) for r, e in rows if r <= MAX_THRESHOLD_RATIO and np.isfinite(e)]
    print(f"largest |error| with u0/sigma_v <= {MAX_THRESHOLD_RATIO:g}: {max(inside):.2%}")


def capacitor() -> None:
    from randvib.analytic.bridge import MIN_CAPACITOR_PERIODS, MIN_LOAD_OVER_COIL

    offered = []
    for psd in (0.25, 1.0):
        for fc in (0.0, 0.005):
            for periods in (1, 2, 4, 8):
                for r_load in (0.5, 2.0, 8.0):
                    friction = rv.Coulomb(fc) if fc > 0 else None
                    omega = np.sqrt(K / M)
                    tau = periods * 2.0 * np.pi / omega
                    coil = rv.BridgeCoil(
                        ALPHA, R_COIL, v_diode=0.01, storage_capacitance=tau / r_load,
                        r_load=r_load,
                    )  # fmt: skip
                    h = rv.Harvester.with_coupling(M, C_M, K, coil, k3=K3, friction=friction)
                    burn = 3.0 * tau + 2.0
                    label = f"S {psd:<5g} Fc {fc:<6g} R_L C {periods} periods, R_L {r_load:<4g}"
                    ratio, error = _compare(h, psd, label, burn_in=burn, t_end=burn + 10.0,
                                            n_paths=64)  # fmt: skip
                    if (
                        ratio <= MAX_THRESHOLD_RATIO
                        and periods >= MIN_CAPACITOR_PERIODS
                        and r_load >= MIN_LOAD_OVER_COIL * R_COIL
                        and np.isfinite(error)
                    ):
                        offered.append(abs(error))
    print(f"largest |error| where the closure is offered: {max(offered):.2%}")


def _compare(h, psd, label, *, burn_in, t_end, n_paths, control_variates=True):
    """Monte Carlo's stored power against the closure's, one printed row: (u0/sigma_v, error).

    The error is NaN where Monte Carlo stores nothing (no ratio to take).
    """
    mc = rv.simulate(
        h, psd, t_end=t_end, burn_in=burn_in, dt=2e-4, n_paths=n_paths, seed=3,
        control_variates=control_variates, progress=False,
    )  # fmt: skip
    ratio, predicted = _closure(h, psd)
    stored = mc.power_stored
    error = np.nan if stored.mean == 0 else predicted / stored.mean - 1.0
    print(
        f"{label} u0/s {ratio:5.2f}  closure {predicted:.4e}  MC {stored.mean:.4e} "
        f"+- {stored.ci95:.1e}  error {error:+.2%}",
        flush=True,
    )
    return ratio, error


def _closure(h, psd):
    """(u0 / sigma_v, stored power) of the closure, computed past its validity limit too."""
    from randvib.analytic import bridge

    coil = h.electrical
    v_out = coil.battery if coil.has_battery else bridge.capacitor_level(h, psd)
    s = bridge._velocity_spread(h, psd, v_out)
    _, mean_abs_i, _ = bridge.bridge_moments(coil, s, v_out)
    stored = v_out * mean_abs_i if coil.has_battery else v_out**2 / coil.r_load
    return (v_out + 2 * coil.v_diode) / coil.alpha / s, stored


if __name__ == "__main__":
    main()
