"""Statistical linearisation of assemblies against a plain-numpy Monte Carlo (run by hand).

python tests/calibration/assembly_linearisation.py [n_paths] [out.txt]

Until the compiled assembly kernel exists, the reference is an independent
simulator written here: stochastic Heun (trapezoidal predictor-corrector,
strong order 1 for additive noise) on the assembly's linear state space
(:meth:`randvib.models.assembly.Assembly.linear_state_space`, checked against
hand-built matrices in tests/test_assembly.py) plus each element's nonlinear
force (k3 u^3 and its friction law, :meth:`Element.nonlinear_force`), with
band-pass input through its two filter states. Every path starts at rest,
burns in ``BURN_IN`` seconds and is averaged over ``DURATION`` seconds; the
95 % interval is 1.96 standard errors of the paths' time averages
(independent paths). The grid is the shipped ``host_with_harvester`` (a
0.05 kg harvester at 10 Hz on a 0.5 kg host mode at 14 Hz, c_e = 0.05 Ns/m):
Coulomb friction on the harvester's coordinate from light to dominant, and
its cubic spring from soft to very hard, under white noise and a band-pass
input at the harvester's frequency.

Each row: the case, the closure's indicators (the element's friction share
and stiffness share, the validity limits of
:mod:`randvib.analytic.assembly_linearisation`), the transducer's power by
the closure and by Monte Carlo with its 95 % half-width, and the relative
error. The last results are kept in ``assembly_linearisation.txt`` beside
this script and quoted in docs/assemblies.md.
"""

from __future__ import annotations

import sys
import time
import warnings

import numba
import numpy as np

import randvib as rv
from randvib.datasets import device_path
from randvib.models.assembly import Assembly

DT = 2e-4  # s: omega dt <= 0.02 at the 14.5 Hz mode
BURN_IN = 6.0  # s: the slowest mode (the harvester, zeta about 0.03) decays e^-7 in energy
DURATION = 40.0  # s averaged per path
SEED = 3100


@numba.njit(cache=True)
def _heun_paths(
    a, b, fa, fb, fc_row, fd, d, push, k3, fc, td, c_e, scale, burn, steps, n_paths, rng
):
    """Per path: the time average of c_e (td . x')^2 after ``burn`` steps (stochastic Heun).

    The state is [x, x', circuit states] followed by the filter's states; every
    product is written as a loop so that a step allocates nothing.
    """
    size, nf, n = b.size, fb.size, d.size
    total_size = size + nf
    out = np.zeros(n_paths)
    z, k1, k2, zp = (
        np.zeros(total_size),
        np.zeros(total_size),
        np.zeros(total_size),
        np.zeros(total_size),
    )
    for path in range(n_paths):
        z[:] = 0.0
        total = 0.0
        for step in range(burn + steps):
            w = scale * rng.standard_normal()
            _drift(a, b, fa, fb, fc_row, fd, d, push, k3, fc, z, w, k1)
            for i in range(total_size):
                zp[i] = z[i] + DT * k1[i]
            _drift(a, b, fa, fb, fc_row, fd, d, push, k3, fc, zp, w, k2)
            for i in range(total_size):
                z[i] += 0.5 * DT * (k1[i] + k2[i])
            if step >= burn:
                v = 0.0
                for i in range(n):
                    v += td[i] * z[n + i]
                total += c_e * v * v
        out[path] = total / steps
    return out


@numba.njit(cache=True, inline="always")
def _drift(a, b, fa, fb, fc_row, fd, d, push, k3, fc, z, w, out):
    """out <- the drift at z: the linear part, the element's k3 u^3 + fc sgn(u'), the filter."""
    size, nf, n = b.size, fb.size, d.size
    acceleration = fd * w
    for i in range(nf):
        acceleration += fc_row[i] * z[size + i]
    u, v = 0.0, 0.0
    for i in range(n):
        u += d[i] * z[i]
        v += d[i] * z[n + i]
    force = k3 * u * u * u + (fc if v > 0 else (-fc if v < 0 else 0.0))  # sgn(0) = 0
    for i in range(size):
        total = b[i] * acceleration + push[i] * force
        for j in range(size):
            total += a[i, j] * z[j]
        out[i] = total
    for i in range(nf):
        total = fb[i] * w
        for j in range(nf):
            total += fa[i, j] * z[size + j]
        out[size + i] = total


def heun_power(assembly: Assembly, excitation, n_paths: int, seed: int):
    """(mean transducer-0 power over paths (W), 95 % half-width (W)) by stochastic Heun.

    For the grid's assemblies: one element (a cubic spring and/or Coulomb friction)
    and one static transducer; white noise enters as its step average,
    sqrt(q / dt) N(0, 1) with q = S/2 (docs/conventions.md).
    """
    (element,) = assembly.elements
    a, b = assembly.linear_state_space()
    n = assembly.n_dof
    shaping = excitation.shaping_filter()
    filt = shaping.system
    row = filt.output("acceleration")
    d = assembly.incidence(element)
    push = np.concatenate(
        [np.zeros(n), -np.linalg.solve(assembly.mass, d), np.zeros(b.size - 2 * n)]
    )
    k3 = element.spring.k3 if element.spring is not None else 0.0
    fc = element.friction.fc if element.friction is not None else 0.0
    transducer = assembly.transducers[0]
    scale = np.sqrt(shaping.noise_intensity / DT)
    power = _heun_paths(
        a, b, filt.a.copy(), filt.b.copy(), filt.c[row].copy(), float(filt.d[row]), d, push,
        float(k3), float(fc), assembly.incidence(transducer), transducer.electrical_damping,
        scale, round(BURN_IN / DT), round(DURATION / DT), n_paths, np.random.default_rng(seed),
    )  # fmt: skip
    return power.mean(), 1.96 * power.std(ddof=1) / np.sqrt(n_paths)


def cases():
    base = Assembly.from_toml(device_path("host_with_harvester"))
    for excitation in (rv.White(0.1), rv.BandPass(0.1, 10.0, 0.1)):
        # the simulator against the exact Lyapunov solution (k3 -> 0: a linear assembly)
        yield "linear (exact)", base.updated({"element.0.k3": 1e-9}), excitation
        for fc in (0.002, 0.01, 0.03, 0.06):
            yield f"coulomb fc={fc:g}", _with_friction(base, fc), excitation
        for k3 in (5e5, 5e6, 2e7):
            yield f"cubic k3={k3:g}", base.updated({"element.0.k3": k3}), excitation


def _with_friction(base: Assembly, fc: float) -> Assembly:
    element = rv.Element((1, 0), friction=rv.Coulomb(fc))
    return Assembly(base.mass, base.stiffness, base.damping, base.influence, (element,),
                    base.transducers)  # fmt: skip


def main(n_paths: int = 200, out: str | None = None) -> None:
    lines = [
        f"# {time.strftime('%Y-%m-%d')}: stochastic Heun dt = {DT} s, {n_paths} paths, "
        f"{BURN_IN} s burn-in + {DURATION} s, seed {SEED}",
        f"{'case':<20} {'input':<10} {'f-share':>8} {'k-share':>8} {'closure W':>11} "
        f"{'MC W':>11} {'+-95%':>9} {'error':>8}",
    ]
    print("\n".join(lines), flush=True)
    for index, (name, assembly, excitation) in enumerate(cases()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prediction = rv.predict(assembly, excitation)
        element = prediction.elements[0]
        closure = prediction.transducers[0].power_electrical
        mean, half = heun_power(assembly, excitation, n_paths, SEED + index)
        line = (
            f"{name:<20} {excitation.name:<10} {element.friction_share:8.3f} "
            f"{element.stiffness_share:8.3f} {closure:11.4e} {mean:11.4e} {half:9.2e} "
            f"{closure / mean - 1:+8.3f}"
        )
        print(line, flush=True)
        lines.append(line)
    if out:
        with open(out, "w") as handle:
            handle.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200, sys.argv[2] if len(sys.argv) > 2 else None)
