"""Subset simulation against crude Monte Carlo on the devices without an exact anchor (by hand).

    NUMBA_NUM_THREADS=1 python tests/calibration/rare_event_devices.py [seeds]

For tests/test_reliability.py, whose estimators are checked against exact
values (linear and friction-free devices under white noise) and against crude
Monte Carlo for the paper's device with friction. Here the devices the issue
names beside them, each at a first-passage probability of 1e-2 to 1e-3 in a
window of 0.2 s (dt = 5e-4 s, Heun), where crude Monte Carlo is affordable:

* ``bridge`` - a coil through a full-wave diode bridge into a 1 V battery
  (V_d = 0.2 V), white noise S = 1;
* ``bistable-coulomb`` - k = -57.4 N/m, k3 = 9.18e6 N/m^3 (wells at +-2.5 mm)
  with the paper's Coulomb friction (5.8 mN), white noise;
* ``piezo-lugre-band-pass`` - the paper's LuGre device (preset lugre-td1)
  with a piezo circuit, under band-pass input (8 Hz, zeta 0.2);
* ``duffing-record`` - k3 = 7e4 N/m^3 driven by a measured record (white,
  2^15 samples at 1 kHz) through its Welch spectrum.

For each seed both estimators run to a c.o.v. of 0.15 and the z-score of
their difference, (subset - crude) / sqrt(se_s^2 + se_c^2), is printed: over
the cases and seeds it should look standard normal. The last results are in
rare_event_devices_results.txt beside this file.
"""

import math
import sys
import time

import numpy as np

import randvib as rv

M = 0.0226
WINDOW, DT = 0.2, 5e-4


def record() -> rv.Measured:
    """A white record, one-sided S = 1 up to 500 Hz (Welch's spectrum drives the paths)."""
    fs = 1000.0
    acc = np.random.default_rng(0).standard_normal(2**15) * math.sqrt(fs / 2.0)
    return rv.Measured(
        rv.Record(time=np.arange(acc.size) / fs, base_acceleration=acc), segment_length=256
    )


def cases() -> dict:
    """name -> (device, excitation, stroke (m))."""
    bridge = rv.BridgeCoil(0.2, 0.5, v_diode=0.2, battery=1.0)
    lugre = rv.preset("lugre-td1").friction  # the paper's identified LuGre law
    piezo = rv.Piezo(theta=0.01, capacitance=1e-6, r_load=2e4)
    return {
        "bridge": (rv.Harvester.with_coupling(M, 0.049, 57.4, bridge), 1.0, 0.02),
        "bistable-coulomb": (
            rv.Harvester(m=M, c_m=0.1, c_e=0.1, k=-57.4, k3=9.18e6, friction=rv.Coulomb(0.0058)),
            1.0,
            0.0062,
        ),
        "piezo-lugre-band-pass": (
            rv.Harvester.with_coupling(M, 0.055, 59.7, piezo, k3=64926.0, friction=lugre),
            rv.BandPass(1.0, 8.0, 0.2),
            0.0023,  # sigma_z about 0.68 mm (simulate)
        ),
        "duffing-record": (rv.Harvester(m=M, c_m=0.1, c_e=0.1, k=57.4, k3=7e4), record(), 0.0115),
    }


def main(seeds: int) -> None:
    zs = []
    for name, (device, excitation, stroke) in cases().items():
        for seed in range(seeds):
            t = time.time()
            out = {}
            for method, extra in (("subset", {"samples_per_level": 300}), ("crude", {})):
                out[method] = rv.first_passage(
                    device, excitation, stroke=stroke, duration=WINDOW, dt=DT, seed=seed,
                    method=method, target_cov=0.15, progress=False, **extra,
                )  # fmt: skip
            s, c = (out[k].probability_first_passage for k in ("subset", "crude"))
            z = (s.mean - c.mean) / math.hypot(s.std_error, c.std_error)
            zs.append(z)
            print(
                f"{name:22s} seed {seed}: subset {s.mean:.3e} (c.o.v. {out['subset'].cov:.2f}, "
                f"{out['subset'].path_steps:.2e} path-steps), crude {c.mean:.3e} "
                f"(c.o.v. {out['crude'].cov:.2f}), z {z:+.2f}; start: {out['subset'].start}; "
                f"{time.time() - t:.0f} s",
                flush=True,
            )
    zs = np.array(zs)
    print(f"{zs.size} comparisons: z mean {zs.mean():+.2f}, SD {zs.std(ddof=1):.2f}, "
          f"max |z| {np.abs(zs).max():.2f}")  # fmt: skip


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
