"""Deterministic response to a recorded input.

Covers randvib.identification.record_response (the public call),
randvib.identification.record_integrator (RK4, stick-slip events, LuGre sub-cycling)
and randvib.identification.input_reconstruction (the differentiated displacement).
"""

import _identification as H
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import randvib as rv
from randvib.identification.input_reconstruction import second_derivative
from randvib.identification.models import MeasurementModel
from randvib.identification.record_response import record_response
from randvib.models.excitation import band_limited_excitation
from randvib.models.record import Record

DUFFING = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0)


def response(params, model, record, input_kind="base_acceleration", **kwargs):
    """record_response of the device of identify's named parameters (``c`` as c_m)."""
    return record_response(H.harvester(params, model), record, input_kind=input_kind, **kwargs)


def _interp_input(u, dt):
    t = np.arange(u.size) * dt
    return lambda s: np.interp(s, t, u)


def _ivp(rhs, y0, t_eval, dt, **kw):
    # max_step = dt keeps the solver from stepping over the input's kinks unseen
    sol = solve_ivp(
        rhs, (0, t_eval[-1]), y0, t_eval=t_eval, rtol=1e-11, atol=1e-14, max_step=dt, **kw
    )
    assert sol.success
    return sol.y


@pytest.fixture(scope="module")
def excitation():
    return band_limited_excitation(2.0, 500.0, 1.5, seed=3)


def test_duffing_matches_solve_ivp(excitation):
    # Same continuous problem (linearly interpolated input) solved by a tight
    # adaptive integrator: the difference is the RK4 error, O(h^4) ~ 1e-7.
    dt = excitation.dt
    acc = _interp_input(excitation["base_acceleration"], dt)
    p = DUFFING

    def rhs(t, y):
        z, v = y
        return [v, -acc(t) - (p["c"] * v + p["k"] * z + p["k3"] * z**3) / p["m"]]

    ref = _ivp(rhs, [1e-4, 0.0], excitation.time, dt)
    sim = response(p, "viscous", excitation, substeps=4, z0=1e-4)
    scale = np.std(ref[0])
    assert np.max(np.abs(sim.z[0] - ref[0])) < 1e-5 * scale
    assert np.max(np.abs(sim.v[0] - ref[1])) < 1e-5 * np.std(ref[1])


def test_rk4_is_fourth_order(excitation):
    ref = response(DUFFING, "viscous", excitation, substeps=64).z[0]
    errs = [
        np.max(np.abs(response(DUFFING, "viscous", excitation, substeps=n).z[0] - ref))
        for n in (1, 2, 4)
    ]
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all((slopes > 3.5) & (slopes < 4.6)), slopes


def test_lugre_matches_stiff_solver(excitation):
    dt = excitation.dt
    acc = _interp_input(excitation["base_acceleration"], dt)
    p = dict(m=0.0226, c=0.055, k=59.7, k3=64926.0)
    s0, s1, fc, fs, vs = 1.98, 0.18, 0.0008, 0.008, 0.007

    def rhs(t, y):
        z, v, th = y
        g = (fc + (fs - fc) * np.exp(-((v / vs) ** 2))) / s0
        rate = v - abs(v) * th / g
        f = s0 * th + s1 * rate
        return [v, -acc(t) - (p["c"] * v + p["k"] * z + p["k3"] * z**3 + f) / p["m"], rate]

    ref = _ivp(rhs, [0.0, 0.0, 0.0], excitation.time, dt, method="LSODA")
    sim = response(
        dict(p, sigma0=s0, sigma1=s1, fc=fc, fs=fs, vs=vs),
        "lugre",
        excitation,
    )
    assert np.max(np.abs(sim.z[0] - ref[0])) < 1e-5 * np.std(ref[0])


def test_moderate_tanh_matches_solve_ivp(excitation):
    dt = excitation.dt
    acc = _interp_input(excitation["base_acceleration"], dt)
    fc, beta = 0.0058, 50.0  # tau = m/(Fc beta) = 78 ms: smooth regime, plain RK4

    def rhs(t, y):
        z, v = y
        f = fc * np.tanh(beta * v)
        return [
            v,
            -acc(t)
            - (DUFFING["c"] * v + DUFFING["k"] * z + DUFFING["k3"] * z**3 + f) / DUFFING["m"],
        ]

    ref = _ivp(rhs, [0.0, 0.0], excitation.time, dt)
    sim = response(dict(DUFFING, fc=fc, beta=beta), "tanh", excitation)
    assert np.max(np.abs(sim.z[0] - ref[0])) < 1e-5 * np.std(ref[0])


# ------------------------------------------------------------------ Coulomb
M, C, K, FC = 1.0, 0.1, 40.0, 1.0
DT = 0.01
T = np.arange(0, 6.0 + DT / 2, DT)
U = 2.5 * np.sin(2 * np.pi * 0.5 * T)  # force input; |u| < Fc near its zeros -> sticking
FORCE = Record(DT, force=U)


def _coulomb_reference():
    """Stick-slip solution by event location with solve_ivp (independent path)."""
    u = _interp_input(U, DT)
    t, z, v = 0.0, 0.0, 0.0
    ts, zs = [0.0], [0.0]
    stuck = abs(u(0.0) - K * z) <= FC
    while t < T[-1] - 1e-12:
        if stuck:
            g = lambda s, z=z: abs(u(s) - K * z) - FC  # noqa: E731
            grid = np.arange(t, T[-1] + DT / 4, DT / 4)
            above = np.nonzero(g(grid) > 0)[0]
            if above.size == 0:
                ts.append(T[-1])
                zs.append(z)
                break
            j = above[0]
            t_new = brentq(g, grid[j - 1], grid[j], xtol=1e-14) if j > 0 else t
            ts.append(t_new)
            zs.append(z)
            t, stuck = t_new, False
            sgn = np.sign(u(t) - K * z)
        else:

            def rhs(s, y, sgn=sgn):
                return [y[1], (u(s) - C * y[1] - K * y[0] - FC * sgn) / M]

            def zero_velocity(s, y, sgn=sgn, t=t):
                return y[1] * sgn if s > t + 1e-9 else 1.0

            zero_velocity.terminal = True
            sol = solve_ivp(
                rhs, (t, T[-1]), [z, v], events=zero_velocity, rtol=1e-12, atol=1e-14,
                max_step=DT, dense_output=True,
            )  # fmt: skip
            seg = T[(T > t) & (T <= sol.t[-1])]
            ts.extend(seg)
            zs.extend(sol.sol(seg)[0])
            t, z, v = sol.t[-1], sol.y[0, -1], 0.0
            ts.append(t)
            zs.append(z)
            if sol.status == 1:
                g = u(t) - K * z
                stuck = abs(g) <= FC
                sgn = np.sign(g)
    return np.interp(T, ts, zs)


def test_coulomb_matches_event_located_reference():
    sim = response(dict(m=M, c=C, k=K, k3=0.0, fc=FC), "coulomb", FORCE, input_kind="force")
    ref = _coulomb_reference()
    # interpolating the reference onto the grid inside stick phases is exact
    # (z constant); the remaining difference is RK4 plus event location error
    assert np.max(np.abs(sim.z[0] - ref)) < 1e-7 * np.max(np.abs(ref))


def test_coulomb_sticks_exactly_without_chattering():
    sim = response(dict(m=M, c=C, k=K, k3=0.0, fc=FC), "coulomb", FORCE, input_kind="force")
    z, v = sim.z[0], sim.v[0]
    stuck = v == 0.0
    assert stuck.mean() > 0.1  # the excitation produces real sticking
    # during a stick the mass does not move at all, and the stick condition holds
    frozen = stuck[1:] & stuck[:-1]
    assert np.all(np.diff(z)[frozen] == 0.0)
    assert np.all(np.abs(U - K * z)[stuck] <= FC + 1e-12)
    # no chattering: at most one stick per half period of the forcing (6 in
    # 6 s), each ending only where the non-friction force really exceeds Fc,
    # and the velocity changes sign only through a stick or one clean crossing
    edges = np.flatnonzero(np.diff(stuck.astype(int)))
    starts = np.r_[0, edges + 1]
    runs = np.diff(np.r_[starts, stuck.size])
    stick_runs = starts[stuck[starts]]
    assert len(stick_runs) <= 7
    for start, length in zip(starts, runs, strict=True):
        end = start + length
        if stuck[start] and end < stuck.size:
            assert abs(U[end] - K * z[end - 1]) > FC
    signs = np.sign(v[~stuck])
    assert np.count_nonzero(np.diff(signs)) <= 7


def test_coulomb_substep_convergence():
    ex = band_limited_excitation(2.0, 500.0, 1.0, seed=4)
    p = dict(DUFFING, fc=0.0058)
    ref = response(p, "coulomb", ex, substeps=32).z[0]
    e1 = np.max(np.abs(response(p, "coulomb", ex, substeps=1).z[0] - ref))
    e4 = np.max(np.abs(response(p, "coulomb", ex, substeps=4).z[0] - ref))
    assert e4 < e1 / 50  # at least ~third order through the stick-slip events
    assert e4 < 1e-6 * np.std(ref)


@pytest.mark.parametrize("beta", [1e7, 4.8e8, 1e9])
def test_stiff_tanh_is_not_a_step_size_artefact(beta):
    ex = band_limited_excitation(2.0, 500.0, 1.0, seed=5)
    p = dict(DUFFING, fc=0.0058)
    coulomb = response(p, "coulomb", ex).z[0]
    runs = [response(dict(p, beta=beta), "tanh", ex, substeps=n).z[0] for n in (1, 4, 16)]
    scale = np.std(coulomb)
    for z in runs:
        assert np.all(np.isfinite(z))
        # tanh -> sgn as beta -> infinity (Eq. 7); the gap is of order 1/(beta sigma_v)
        assert np.max(np.abs(z - coulomb)) < 2e3 / beta * scale / 0.05
    assert np.max(np.abs(runs[0] - runs[-1])) < 1e-4 * scale


def test_batch_equals_individual_runs(excitation):
    fcs = np.array([0.0, 0.002, 0.0058, 0.02])
    batch = response(dict(DUFFING, fc=fcs), "coulomb", excitation)
    for i, fc in enumerate(fcs):
        one = response(dict(DUFFING, fc=fc), "coulomb", excitation)
        np.testing.assert_array_equal(batch.z[i], one.z[0])


def test_zero_friction_equals_viscous(excitation):
    a = response(dict(DUFFING, fc=0.0), "coulomb", excitation).z
    b = response(DUFFING, "viscous", excitation).z
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-15)


def test_base_displacement_input_agrees_with_acceleration():
    ex = band_limited_excitation(4.0, 1000.0, 1.0, seed=6)
    a = response(DUFFING, "viscous", ex).z[0]
    d = response(DUFFING, "viscous", ex, input_kind="base_displacement").z[0]
    # fourth-order differentiation inside, second order at the record's ends
    assert np.max(np.abs(a - d)) < 1e-3 * np.std(a)


def test_second_derivative_is_fourth_order():
    errs = []
    for dt in (0.01, 0.005):
        t = np.arange(0, 2, dt)
        a = second_derivative(np.sin(3 * t), dt)
        errs.append(np.max(np.abs(a[2:-2] + 9 * np.sin(3 * t[2:-2]))))
    assert 14 < errs[0] / errs[1] < 18


def test_diverging_candidate_is_flagged():
    # an unstable spring (k < 0, no cubic term) runs away: NaN from the sample it leaves
    # the response limit on
    device = rv.Harvester(m=1.0, c_m=0.1, c_e=0.0, k=-1e4, k3=0.0)
    sim = record_response(device, Record(0.01, force=np.ones(50)), response_limit=10.0)
    assert np.isnan(sim.z[0, -1]) and np.isfinite(sim.z[0, 0])


def test_measurement_model_offsets_the_input_not_the_response():
    """The input offset is taken off the input (measured = true + offset); the response is
    the true displacement, without the output offset."""
    device = rv.Harvester(m=1.0, c_m=0.3, c_e=0.0, k=40.0, k3=4e4)
    u = np.random.default_rng(0).standard_normal(300)
    true = record_response(device, Record(0.02, force=u)).z
    offsets = MeasurementModel(input_offset=0.7, output_offset=1e-3)
    measured = record_response(device, Record(0.02, force=u + 0.7), measurement=offsets).z
    np.testing.assert_allclose(measured, true, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(harvester=DUFFING), "record_response needs a randvib.Harvester"),
        (dict(record=np.zeros(10)), "`record` must be a randvib.Record"),
        (dict(substeps=0), "`substeps` must be an integer >= 1"),
        (dict(hold="quintic"), "`hold` must be one of"),
        (dict(input_kind="velocity"), "`input_kind` must be one of"),
        (dict(input_kind="force"), "has no 'force' channel"),
        (
            dict(record=Record(0.01, force=np.zeros(10), base_acceleration=np.zeros(10))),
            "several input channels",
        ),
        (dict(measurement={"k2": 1.0}), "`measurement` must be a randvib.MeasurementModel"),
        # a coil with inductance is no longer refused: the record simulation carries its
        # current (issue 34; tests/test_electrical_identification.py checks it against RK4)
    ],
)
def test_bad_arguments(kwargs, match):
    args = dict(
        harvester=rv.Harvester(m=1.0, c_m=0.1, c_e=0.0, k=1.0),
        record=Record(0.01, base_acceleration=np.zeros(10)),
    )
    args.update(kwargs)
    with pytest.raises((ValueError, KeyError), match=match):
        record_response(**args)
