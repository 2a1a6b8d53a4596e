"""Monte Carlo of assemblies: pathwise against plain numpy and the single mass, exact linear cases.

Covers :func:`randvib.simulate` with an :class:`~randvib.Assembly`:
:mod:`randvib.montecarlo.assembly_simulation` (driver and argument checks),
:mod:`randvib.montecarlo.assembly_kernel` (the compiled kernel),
:mod:`randvib.montecarlo.assembly_setup` (its tables),
:mod:`randvib.montecarlo.assembly_step_check` (the step check on the
linearised assembly) and :mod:`randvib.montecarlo.assembly_results`.

* **Pathwise**: an independent simulator written here in plain numpy from
  docs/conventions.md (not from the package's code) takes the same Brownian
  increments; every state (displacements, velocities, friction, circuit and
  bridge states) agrees at every step to rounding, for Euler-Maruyama and
  Heun, with Coulomb, tanh and LuGre friction, cubic and quadratic springs, a
  coil with inductance, a piezo element and a coil bridge into a battery, on
  three DOFs with a full mass matrix and a non-trivial influence vector. A
  one-DOF assembly equals the single-mass ``rv.simulate`` of the same
  Harvester on the same increments, state by state.
* **Exact linear**: a two-DOF chain and a host with two harvesters (coil
  circuits) against the Lyapunov solution built here by hand, with the
  scheme's own exact discrete covariance (the same step written as a linear
  recursion) as the known time-step bias; and at a coarse step against that
  discrete covariance alone. Intervals and power: tests/_stats.py.
* **Energy balance** under white noise with the declared parameters.
* Reproducibility (threads, batches), the CLI's ``--device`` JSON, refusals.
"""

import json

import numpy as np
import pytest
from _cli import run as run_cli
from _stats import assert_matches
from scipy import linalg

import randvib as rv
from randvib.datasets import device_path
from randvib.models.excitation import BandLimited, BandPass

# ------------------------------------------------------------ the numpy reference
# Written from docs/conventions.md ("Assemblies", the friction laws, "Inductive
# coil", "Piezoelectric", "Full-wave bridge with a coil"); the increments enter
# every velocity as r sqrt(S/2) dW, as the single mass's conventions write the
# SDE (dv = ... + sqrt(S/2) dW).


def _friction(law, du, theta):
    """(F, theta') of ("coulomb", Fc), ("tanh", Fc, beta) or ("lugre", s0, s1, Fc, Fs, vs)."""
    if law is None:
        return 0.0 * du, 0.0 * du
    if law[0] == "coulomb":
        return law[1] * np.sign(du), 0.0 * du
    if law[0] == "tanh":
        return law[1] * np.tanh(law[2] * du), 0.0 * du
    _, s0, s1, fc, fs, vs = law
    g = (fc + (fs - fc) * np.exp(-((du / vs) ** 2))) / s0
    rate = du - np.abs(du) * theta / g
    return s0 * theta + s1 * rate, rate


def _coordinate(q, between):
    i, j = between
    return q[:, i] - (0.0 if j is None else q[:, j])


def _apply(force_on_dofs, between, f):
    i, j = between
    force_on_dofs[:, i] += f
    if j is not None:
        force_on_dofs[:, j] -= f


def numpy_drift(spec, x, v, theta, s):
    """Rates (x', v', theta', s') and the bridges' currents, all paths at once."""
    force = x @ spec["K"].T + v @ spec["C"].T
    theta_rate = np.zeros_like(theta)
    for e, el in enumerate(spec["elements"]):
        u, du = _coordinate(x, el["between"]), _coordinate(v, el["between"])
        f_fr, theta_rate[:, e] = _friction(el.get("friction"), du, theta[:, e])
        f = el.get("k", 0.0) * u + el.get("k2", 0.0) * u**2 + el.get("k3", 0.0) * u**3
        _apply(force, el["between"], f + el.get("damping", 0.0) * du + f_fr)
    s_rate = np.zeros_like(s)
    currents = []
    for t, tr in enumerate(spec["transducers"]):
        du = _coordinate(v, tr["between"])
        kind = tr["kind"]
        if kind == "c_e":
            _apply(force, tr["between"], tr["c_e"] * du)
        elif kind == "coil":  # L i' + (R_L + R_C) i = alpha u', force alpha i
            _apply(force, tr["between"], tr["alpha"] * s[:, t])
            s_rate[:, t] = (tr["alpha"] * du - (tr["r_load"] + tr["r_coil"]) * s[:, t]) / tr["L"]
        elif kind == "piezo":  # C_p V' + V / R_L = theta u', force theta V
            _apply(force, tr["between"], tr["theta"] * s[:, t])
            s_rate[:, t] = (tr["theta"] * du - s[:, t] / tr["r_load"]) / tr["C_p"]
        else:  # a coil bridge into a battery: i = sgn(e) max(0, |e| - V_b - 2 V_d) / R_C
            e = tr["alpha"] * du
            i = np.sign(e) * np.maximum(0.0, np.abs(e) - tr["V_b"] - 2 * tr["V_d"]) / tr["r_coil"]
            _apply(force, tr["between"], tr["alpha"] * i)
            currents.append(i)
    acceleration = -linalg.solve(spec["M"], force.T).T
    return v, acceleration, theta_rate, s_rate, currents


def numpy_paths(spec, dw, dt, psd, x0, v0, scheme, forcing=None):
    """Every path's states at every step, and each bridge's stored energy / time (V_b E|i|).

    ``forcing``: (paths, steps) velocity increments u_n = -int a dt of tones or shocks
    over each step, given to every velocity through r half before and half after the
    scheme's step (docs/conventions.md, "Tones"); the states are those before the first half.
    """
    paths, steps = dw.shape
    r = spec["r"]
    x, v = np.tile(x0, (paths, 1)), np.tile(v0, (paths, 1))
    theta = np.zeros((paths, len(spec["elements"])))
    s = np.zeros((paths, len(spec["transducers"])))
    states, stored = [], np.zeros((paths, len(spec["transducers"])))
    for step in range(steps + 1):
        states.append((x.copy(), v.copy(), theta.copy(), s.copy()))
        if step == steps:
            break
        noise = np.sqrt(psd / 2.0) * dw[:, step][:, None] * r[None, :]
        half = 0.0 if forcing is None else 0.5 * forcing[:, step][:, None] * r[None, :]
        v = v + half
        k1 = numpy_drift(spec, x, v, theta, s)
        if scheme == "euler-maruyama":
            weights, stages = (1.0,), (k1,)
        else:
            xp, vp = x + k1[0] * dt, v + k1[1] * dt + noise
            k2 = numpy_drift(spec, xp, vp, theta + k1[2] * dt, s + k1[3] * dt)
            weights, stages = (0.5, 0.5), (k1, k2)

        def mean(q, weights=weights, stages=stages):
            return sum(w * st[q] for w, st in zip(weights, stages, strict=True))

        x, v = x + mean(0) * dt, v + mean(1) * dt + noise + half
        theta, s = theta + mean(2) * dt, s + mean(3) * dt
        bridges = [t for t, tr in enumerate(spec["transducers"]) if tr["kind"] == "bridge"]
        for slot, t in enumerate(bridges):
            current = sum(w * np.abs(st[4][slot]) for w, st in zip(weights, stages, strict=True))
            stored[:, t] += spec["transducers"][t]["V_b"] * current * dt
    return states, stored / (steps * dt)


def assembly_of(spec) -> rv.Assembly:
    """The package's Assembly of a numpy spec (parts in the spec's order)."""
    laws = {"coulomb": rv.Coulomb, "tanh": rv.Tanh, "lugre": rv.LuGre}
    elements = []
    for el in spec["elements"]:
        law = el.get("friction")
        spring = rv.Spring(el.get("k", 0.0), el.get("k2", 0.0), el.get("k3", 0.0))
        friction = None if law is None else laws[law[0]](*law[1:])
        elements.append(rv.Element(el["between"], spring, friction, el.get("damping", 0.0)))
    transducers = []
    for tr in spec["transducers"]:
        coupling = {
            "c_e": lambda t: t["c_e"],
            "coil": lambda t: rv.Inductive(t["alpha"], t["r_load"], t["r_coil"], t["L"]),
            "piezo": lambda t: rv.Piezo(t["theta"], t["C_p"], t["r_load"]),
            "bridge": lambda t: rv.BridgeCoil(
                alpha=t["alpha"], r_coil=t["r_coil"], v_diode=t["V_d"], battery=t["V_b"]
            ),
        }[tr["kind"]](tr)
        transducers.append(rv.Transducer(tr["between"], coupling))
    return rv.Assembly(spec["M"], spec["K"], spec["C"], spec["r"], elements, transducers)


#: Three DOFs: a host (0) with a full mass matrix and an influence below 1 on DOF 2, a Duffing
#: harvester with Coulomb friction and a coil on DOF 1, a LuGre harvester with a quadratic
#: spring and a piezo element on DOF 2, a tanh damper between the two, a coil bridge into a
#: battery on the host, and a bare c_e.
SPEC = {
    "M": np.array([[0.5, 0.01, 0.0], [0.01, 0.03, 0.0], [0.0, 0.0, 0.04]]),
    "K": np.array([[4000.0, -60.0, 0.0], [-60.0, 60.0, 0.0], [0.0, 0.0, 0.0]]),
    "C": np.array([[0.6, -0.02, 0.0], [-0.02, 0.02, 0.0], [0.0, 0.0, 0.0]]),
    "r": np.array([1.0, 1.0, 0.8]),
    "elements": [
        {"between": (1, 0), "k3": 5e5, "friction": ("coulomb", 0.006)},
        {"between": (2, 0), "k": 90.0, "k2": 3e3, "damping": 0.03,
         "friction": ("lugre", 2.0, 0.18, 0.004, 0.008, 0.007)},
        {"between": (2, 1), "friction": ("tanh", 0.002, 300.0)},
    ],
    "transducers": [
        {"between": (1, 0), "kind": "coil", "alpha": 0.2, "r_load": 1.0, "r_coil": 0.5, "L": 2e-3},
        {"between": (2, 0), "kind": "piezo", "theta": 2e-3, "C_p": 1e-7, "r_load": 1e5},
        {"between": (0, None), "kind": "bridge", "alpha": 2.0, "r_coil": 5.0, "V_d": 0.1,
         "V_b": 0.3},
        {"between": (2, 1), "kind": "c_e", "c_e": 0.01},
    ],
}  # fmt: skip


@pytest.mark.parametrize("scheme", ["euler-maruyama", "heun"])
def test_every_state_equals_an_independent_numpy_simulator(scheme):
    """Same increments: x, v, friction and circuit states agree at every step to rounding.

    300 steps of 1e-4 s from a moving start, 3 paths; the bridge's stored power
    V_b E|i| and each part's per-path statistics agree too.
    """
    psd, dt, steps, paths = 2.0, 1e-4, 300, 3
    dw = np.random.default_rng(7).normal(0.0, np.sqrt(dt), (paths, steps))
    x0, v0 = np.array([1e-4, 2e-3, -1e-3]), np.array([0.01, -0.05, 0.08])
    states, stored = numpy_paths(SPEC, dw, dt, psd, x0, v0, scheme)
    assembly = assembly_of(SPEC)
    result = rv.simulate(
        assembly, psd, t_end=steps * dt, dt=dt, n_paths=paths, dW=dw, initial=(x0, v0),
        scheme=scheme, record_paths=paths, progress=False, check_step=False,
    )  # fmt: skip
    record = result.histories
    n = 3
    circuits = [0, 1]  # the coil's current and the piezo's voltage, in transducer order
    for step, (x, v, theta, s) in enumerate(states):
        got = record.state[:, step]
        np.testing.assert_allclose(got[:, :n], x, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(got[:, n + 1 : 2 * n + 1], v, rtol=1e-9, atol=1e-13)
        np.testing.assert_allclose(got[:, 2 * n + 2 : 2 * n + 5], theta, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(
            got[:, 2 * n + 5 : 2 * n + 7], s[:, circuits], rtol=1e-9, atol=1e-12
        )
    bridge = result.transducers[2]
    power = np.array(result.transducer_power(2)[1])
    np.testing.assert_allclose(power, stored[:, 2], rtol=1e-9)
    assert bridge.power_stored.mean == pytest.approx(np.mean(stored[:, 2]), rel=1e-9)
    # the coil's power from its current, the window's average over the numpy states
    currents = np.array([s[:, 0] for _, _, _, s in states[:-1]])
    coil = (SPEC["transducers"][0]["r_load"] + 0.5) * np.mean(currents**2, axis=0)
    np.testing.assert_allclose(result.transducer_power(0)[0], coil, rtol=1e-9)


HARVESTERS = {
    "duffing-coulomb": rv.preset("figure9").updated(k3=5e5),
    "lugre": rv.preset("lugre-td1").updated(c_e=0.05),
    "coil": rv.Harvester.with_coupling(
        0.0226, 0.05, 57.4, rv.Inductive(0.1992, 1.0, 0.48, 1e-3), k3=5e5, friction=rv.Tanh(0.004, 800.0)
    ),
    "piezo": rv.Harvester.with_coupling(0.0226, 0.05, 57.4, rv.Piezo(1e-3, 1e-7, 1e5)),
    "coil-bridge": rv.Harvester.with_coupling(
        0.0226, 0.05, 57.4, rv.BridgeCoil(alpha=1.0, r_coil=2.0, v_diode=0.1, battery=0.2)
    ),
    "piezo-bridge": rv.Harvester.with_coupling(
        0.0226, 0.05, 57.4, rv.BridgePiezo(theta=1e-3, capacitance=1e-7, v_diode=0.1, battery=0.5)
    ),
}  # fmt: skip


@pytest.mark.filterwarnings("ignore::randvib.montecarlo.step_check.StepSizeWarning")
@pytest.mark.parametrize("scheme", ["euler-maruyama", "heun"])
@pytest.mark.parametrize("name", list(HARVESTERS))
def test_one_dof_assembly_equals_the_single_mass_simulation(name, scheme):
    """The Harvester as a one-DOF assembly: z, v at every step and each path's power, to rounding."""
    h = HARVESTERS[name]
    dt, steps, paths = 1e-4, 400, 3
    dw = np.random.default_rng(3).normal(0.0, np.sqrt(dt), (paths, steps))
    common = dict(t_end=steps * dt, dt=dt, n_paths=paths, dW=dw, scheme=scheme, progress=False,
                  record_paths=paths, check_step=False)  # fmt: skip
    single = rv.simulate(h, 1.0, initial=(2e-3, 0.05), **common)
    assembly = rv.simulate(rv.Assembly.from_harvester(h), 1.0, initial=([2e-3], [0.05]), **common)
    np.testing.assert_allclose(
        assembly.histories.x[:, :, 0], single.histories.z, rtol=1e-10, atol=1e-16
    )
    np.testing.assert_allclose(
        assembly.histories.v[:, :, 0], single.histories.v, rtol=1e-10, atol=1e-14
    )
    electrical, _ = assembly.transducer_power(0)
    avg = single.averages
    if h.is_rectified:
        expected = avg.stored_power + avg.coil_loss + avg.diode_loss
    elif h.has_circuit:
        expected = h.electrical.power_electrical(avg.v2, avg.circuit_square)
    else:
        expected = h.c_e * avg.v2
    np.testing.assert_allclose(electrical, expected, rtol=1e-9, atol=1e-18)
    if h.friction is not None:  # the one element's friction power u' F
        np.testing.assert_allclose(
            assembly.per_path[:, assembly.columns.friction], single.averages.friction_power,
            rtol=1e-9, atol=1e-18,
        )  # fmt: skip


@pytest.mark.filterwarnings("ignore::randvib.montecarlo.step_check.StepSizeWarning")
@pytest.mark.parametrize(
    "name, excitation",
    [("duffing-coulomb", BandPass(1.0, 8.0, 0.2)), ("coil", BandLimited(1.0, 4.0, 20.0))],
)
def test_one_dof_assembly_equals_the_single_mass_under_coloured_input(name, excitation):
    """A shaping filter (band-pass) and a synthesised spectrum: the same paths, state by state."""
    h = HARVESTERS[name]
    common = dict(t_end=0.05, dt=1e-4, n_paths=3, seed=5, progress=False, record_paths=3,
                  check_step=False)  # fmt: skip
    single = rv.simulate(h, excitation, initial="rest", **common)
    assembly = rv.simulate(rv.Assembly.from_harvester(h), excitation, initial="rest", **common)
    np.testing.assert_allclose(
        assembly.histories.x[:, :, 0], single.histories.z, rtol=1e-10, atol=1e-16
    )
    np.testing.assert_allclose(
        assembly.histories.v[:, :, 0], single.histories.v, rtol=1e-10, atol=1e-14
    )


def test_one_dof_assembly_equals_the_single_mass_on_a_record():
    """A measured record cut into segments: each segment's velocity variance, to rounding."""
    t = np.arange(4000) * 1e-3
    acceleration = np.random.default_rng(11).standard_normal(t.size)
    record = rv.Measured(rv.Record(time=t, base_acceleration=acceleration))
    h = HARVESTERS["duffing-coulomb"]
    common = dict(segments=4, burn_in=0.2, substeps=4, seed=2, progress=False, check_step=False,
                  initial="rest")  # fmt: skip
    single = rv.monte_carlo_on_record(h, record, **common)
    assembly = rv.monte_carlo_on_record(rv.Assembly.from_harvester(h), record, **common)
    np.testing.assert_allclose(
        assembly.per_path[:, assembly.columns.vv], single.averages.v2, rtol=1e-9
    )
    np.testing.assert_allclose(
        assembly.per_path[:, assembly.columns.xx], single.averages.z2, rtol=1e-9
    )


# ---------------------------------------------------------- exact linear cases
#: A host (DOF 0) with two linear harvesters (DOFs 1, 2), each with a coil (inductance).
HOST = {
    "M": np.diag([0.5, 0.05, 0.05]),
    "K": np.array([[4000.0 + 180 + 230, -180, -230], [-180, 180, 0], [-230, 0, 230]]),
    "C": np.array([[4.0 + 0.6 + 0.6, -0.6, -0.6], [-0.6, 0.6, 0], [-0.6, 0, 0.6]]),
    "r": np.ones(3),
    "elements": [],
    "transducers": [
        {"between": (1, 0), "kind": "coil", "alpha": 0.2, "r_load": 1.0, "r_coil": 0.5, "L": 2e-3},
        {"between": (2, 0), "kind": "coil", "alpha": 0.25, "r_load": 2.0, "r_coil": 0.5, "L": 3e-3},
    ],
}  # fmt: skip
#: A two-DOF chain (0.2 kg on the base, 0.05 kg on it), a resistive c_e between the masses.
CHAIN = {
    "M": np.diag([0.2, 0.05]),
    "K": np.array([[2000.0 + 200, -200], [-200, 200]]),
    "C": np.array([[2.0 + 0.3, -0.3], [-0.3, 0.3]]),
    "r": np.ones(2),
    "elements": [],
    "transducers": [{"between": (1, 0), "kind": "c_e", "c_e": 0.2}],
}


def _incidence(between, n):
    d = np.zeros(n)
    d[between[0]] = 1.0
    if between[1] is not None:
        d[between[1]] = -1.0
    return d


def linear_system(spec, filter_system=None):
    """(A, G) of the state [x, v, circuit states, filter states]: dy = A y dt + G dW (unit dW).

    Written from docs/conventions.md: M x'' + C x' + K x + forces = -M r a; a
    coil L i' = alpha u' - (R_L + R_C) i pushes alpha i; a static c_e pushes
    c_e u'. White input: a dt = sqrt(S/2) dW reaches v through r (G carries
    sqrt(S/2) = 1 here, scaled by the caller). A filter's output c z is a.
    """
    n = spec["M"].shape[0]
    coils = [t for t in spec["transducers"] if t["kind"] == "coil"]
    nf = 0 if filter_system is None else filter_system[0].shape[0]
    size = 2 * n + len(coils) + nf
    m_inv = np.linalg.inv(spec["M"])
    damping = spec["C"].copy()
    for t in spec["transducers"]:
        if t["kind"] == "c_e":
            d = _incidence(t["between"], n)
            damping += t["c_e"] * np.outer(d, d)
    a = np.zeros((size, size))
    a[:n, n : 2 * n] = np.eye(n)
    a[n : 2 * n, :n] = -m_inv @ spec["K"]
    a[n : 2 * n, n : 2 * n] = -m_inv @ damping
    for q, t in enumerate(coils):
        d, row = _incidence(t["between"], n), 2 * n + q
        a[n : 2 * n, row] = -m_inv @ (t["alpha"] * d)
        a[row, n : 2 * n] = t["alpha"] * d / t["L"]
        a[row, row] = -(t["r_load"] + t["r_coil"]) / t["L"]
    g = np.zeros(size)
    if filter_system is None:
        g[n : 2 * n] = spec["r"]
    else:
        fa, fb, fc = filter_system
        a[2 * n + len(coils) :, 2 * n + len(coils) :] = fa
        a[n : 2 * n, 2 * n + len(coils) :] = -np.outer(spec["r"], fc)
        g[2 * n + len(coils) :] = fb
    return a, g


def covariances(a, g, dt, scheme):
    """(continuous Lyapunov P, the scheme's exact stationary covariance of the recursion)."""
    continuous = linalg.solve_continuous_lyapunov(a, -np.outer(g, g))
    eye = np.eye(a.shape[0])
    if scheme == "euler-maruyama":
        step, noise = eye + a * dt, g
    else:  # Heun: y+ = y + (A y + A (y + A y dt + g dW)) dt / 2 + g dW
        step, noise = eye + a * dt + a @ a * dt**2 / 2, (eye + a * dt / 2) @ g
    discrete = linalg.solve_discrete_lyapunov(step, np.outer(noise, noise) * dt)
    return continuous, discrete


def _quantities(spec, p):
    """Per DOF E[x^2], E[v^2]; per transducer power_electrical; all dissipation; from covariance P."""
    n = spec["M"].shape[0]
    out = {f"x{i}": p[i, i] for i in range(n)} | {f"v{i}": p[n + i, n + i] for i in range(n)}
    dissipated = np.trace(spec["C"] @ p[n : 2 * n, n : 2 * n])
    coil = 0
    for t_index, t in enumerate(spec["transducers"]):
        if t["kind"] == "coil":
            power = (t["r_load"] + t["r_coil"]) * p[2 * n + coil, 2 * n + coil]
            coil += 1
        else:
            d = _incidence(t["between"], n)
            power = t["c_e"] * d @ p[n : 2 * n, n : 2 * n] @ d
        out[f"power{t_index}"] = power
        dissipated += power
    out["dissipated"] = dissipated
    return out


@pytest.mark.parametrize(
    "spec, scheme, excitation",
    [
        (HOST, "heun", 0.2),
        (HOST, "euler-maruyama", 0.2),
        (CHAIN, "heun", BandPass(0.2, 12.0, 0.3)),
    ],
    ids=["host-heun-white", "host-euler-white", "chain-heun-band-pass"],
)  # fmt: skip
def test_linear_assembly_matches_the_lyapunov_solution(spec, scheme, excitation):
    """Per-DOF variances, per-transducer power and (white) the energy balance, against Lyapunov.

    256 paths x 6 s (1 s burn-in), dt = 5e-4 s: each estimate within 4 standard
    errors of the continuous Lyapunov value plus the scheme's exact time-step
    bias (the stationary covariance of the same step as a linear recursion,
    ``covariances``), and powered to see a 10 % error (2 % for the energy
    balance with its control variates, which hold the exact input power
    r^T M r S / 4).
    """
    dt, white = 5e-4, not isinstance(excitation, BandPass)
    filter_system = None
    if not white:
        system = excitation.shaping_filter().system
        filter_system = (system.a, system.b, system.c[system.output("acceleration")])
    a, g = linear_system(spec, filter_system)
    level = excitation if white else excitation.level
    continuous, discrete = (np.sqrt(level / 2.0) ** 2 * c for c in covariances(a, g, dt, scheme))
    exact, stepped = _quantities(spec, continuous), _quantities(spec, discrete)
    result = rv.simulate(
        assembly_of(spec), excitation, t_end=6.0, dt=dt, n_paths=256, burn_in=1.0, scheme=scheme,
        seed=4, progress=False, check_step=False, control_variates=True,
    )  # fmt: skip
    n = spec["M"].shape[0]
    for i in range(n):
        for kind, stats in (("x", result.displacement_variance), ("v", result.velocity_variance)):
            key = f"{kind}{i}"
            assert_matches(stats[i], exact[key], detect=0.1, known_bias=stepped[key] - exact[key],
                           what=f"E[{key}^2]")  # fmt: skip
    for index, transducer in enumerate(result.transducers):
        key = f"power{index}"
        assert_matches(transducer.power_electrical, exact[key], detect=0.1,
                       known_bias=stepped[key] - exact[key], what=key)  # fmt: skip
    if white:
        r = spec["r"]
        assert exact["dissipated"] == pytest.approx(r @ spec["M"] @ r * level / 4.0, rel=1e-9)
        assert result.power_input == pytest.approx(r @ spec["M"] @ r * level / 4.0, rel=1e-15)
        assert_matches(result.power_dissipated, exact["dissipated"], detect=0.02,
                       known_bias=stepped["dissipated"] - exact["dissipated"],
                       what="power_dissipated")  # fmt: skip


@pytest.mark.filterwarnings("ignore::randvib.montecarlo.step_check.StepSizeWarning")
def test_energy_balance_of_the_nonlinear_assembly():
    """Every dissipation (dashpots, friction incl. LuGre, circuits, the bridge) = r^T M r S / 4.

    SPEC under white noise S = 0.2, Heun, dt = 2e-5 s, 64 paths x 0.6 s from
    rest (0.1 s burn-in), with the energy-balance control variates: the
    residual within 4 standard errors (0.13 % of the input power each) and
    powered to see 2 % of it. The scheme's own bias, measured on the same
    paths by changing dt (tests/calibration/assembly_energy_balance.py and its
    .txt): residual -0.92 % at 4e-5 s, -0.13 % at 2e-5 s, +0.02 % at 1e-5 s,
    so about one standard error here. (At S = 2 the quadratic spring's
    barrier at u = -k/k2 = -3 cm is crossed and a path escapes.)
    """
    result = rv.simulate(
        assembly_of(SPEC), 0.2, t_end=0.6, dt=2e-5, n_paths=64, burn_in=0.1, seed=9,
        progress=False, control_variates=True, initial="rest",
    )  # fmt: skip
    assert result.power_input == pytest.approx(SPEC["r"] @ SPEC["M"] @ SPEC["r"] * 0.2 / 4.0)
    assert_matches(result.power_dissipated, result.power_input, detect=0.02,
                   what="power_dissipated")  # fmt: skip


def test_results_do_not_depend_on_batches():
    """Path i draws from stream (seed, i): one batch or three give the same per-path numbers."""
    common = dict(t_end=0.02, dt=1e-4, n_paths=20, seed=3, progress=False, check_step=False)
    whole = rv.simulate(assembly_of(SPEC), 1.0, **common)
    parts = rv.simulate(assembly_of(SPEC), 1.0, batch_paths=8, **common)
    np.testing.assert_array_equal(whole.per_path, parts.per_path)
    later = rv.simulate(assembly_of(SPEC), 1.0, first_path=8, **(common | {"n_paths": 12}))
    np.testing.assert_array_equal(whole.per_path[8:], later.per_path)


def test_cli_simulate_device_json(capsys, tmp_path):
    """``randvib simulate --device FILE --json``: the issue's keys, equal to rv.simulate on the file."""
    path = tmp_path / "host.toml"
    path.write_text(device_path("two_harvesters_on_host").read_text())
    argv = ["simulate", "--device", path, "--psd", "0.1", "--t-end", "0.3", "--burn-in", "0.1",
            "--paths", "16", "--seed", "3", "--json"]  # fmt: skip
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    data = json.loads(out)
    expected = rv.simulate(
        rv.Assembly.from_toml(path), 0.1, t_end=0.3, dt=1e-4, n_paths=16, burn_in=0.1, seed=3,
        progress=False,
    )  # fmt: skip
    assert data["n_dof"] == 3 and len(data["transducers"]) == 2
    assert len(data["displacement_variance"]) == len(data["velocity_variance"]) == 3
    for got, want in zip(data["transducers"], expected.transducers, strict=True):
        assert got["power_electrical"]["mean"] == want.power_electrical.mean
        assert got["power_electrical"]["ci95"] == want.power_electrical.ci95
        assert got["power_load"]["mean"] == want.power_load.mean
    for got, want in zip(data["velocity_variance"], expected.velocity_variance, strict=True):
        assert got == want.to_dict()
    assert data["power_input"] == pytest.approx(expected.power_input)


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"companion": True}, "`companion`"),
        ({"histogram_bins": 10}, "`histogram_bins`"),
        ({"initial": ([0.0], [0.0])}, "`initial` must be"),
        ({"dW": np.zeros((2, 3))}, "`dW` must have shape"),
        ({"control_variates": True, "psd": BandLimited(1.0, 4.0, 20.0)}, "`control_variates`"),
        (
            {"psd": rv.BandPass(1.0, 8.0, 0.1) + rv.Tone(25.0, 0.5), "control_variates": True},
            "`control_variates` needs Gaussian noise alone",
        ),
    ],
)
def test_assembly_refusals_name_the_argument(kwargs, fragment):
    psd = kwargs.pop("psd", 1.0)
    with pytest.raises(ValueError, match=fragment):
        rv.simulate(assembly_of(CHAIN), psd, t_end=0.01, dt=1e-4, n_paths=2, progress=False,
                    check_step=False, **kwargs)  # fmt: skip
