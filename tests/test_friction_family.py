"""A friction law defined only here runs through every consumer.

``Stribeck`` below is declared in this file and nowhere in the package:
Coulomb friction plus a static peak that decays with speed,

    F = (Fc + (Fs - Fc) exp(-(v/vs)^2)) s(v),   s = sgn(v) if vt = 0, else tanh(v/vt).

Its one class declaration (parameters with units and search bounds, numpy
force, numba kernel) is all that Monte Carlo (:func:`randvib.simulate`),
record simulation, identification, equivalent linearisation and the CLI's
registry need. Each is checked against an independent number:

* Fs = Fc, vt = 0 is Coulomb friction: Monte Carlo through the law's compiled
  callback must reproduce the built-in inlined Coulomb kernel bit for bit, and
  linearisation must reproduce the closed form Eq. 30;
* Fs = Fc, vt > 0 is ``Tanh(Fc, 1/vt)``: record simulation must reproduce the
  built-in law's RK4 path to rounding;
* Fs > Fc: Monte Carlo must satisfy the energy identity
  c E[v^2] + E[v F] = S m / 4 (docs/conventions.md), and identification must
  recover the parameters of a noise-free record it simulated itself.

Why a tanh regularisation for the record simulator: the record simulator's
exact event-located stick-slip integrator is declared per law through
``stick_slip`` (a law that is ``p[0] sgn v`` or ``p[0] tanh(p[1] v)``); a law
with a speed-dependent sliding force and a separate breakaway level (Fs) is
not of that form, so it is integrated with plain RK4, which needs the force
smooth on the scale of the step. Monte Carlo (Euler-Maruyama/Heun) and the
Gaussian quadrature of linearisation take the discontinuous law as it is.

Covers the friction family's declarations (:mod:`randvib.models.friction`,
:mod:`randvib.models.parameters`) as every consumer reads them: the CLI's options
(:mod:`randvib.cli._device`), identification (:mod:`randvib.identification.models`,
:mod:`randvib.identification.bounds`, :mod:`randvib.identification.record_integrator`)
and the Monte Carlo kernel.
"""

from dataclasses import dataclass

import _identification as H
import numba
import numpy as np
import pytest
from _stats import assert_matches
from scipy import integrate

import randvib as rv
from randvib.cli._device import FRICTION_CHOICES
from randvib.identification.bounds import default_bounds
from randvib.identification.identify import identify
from randvib.identification.models import MODELS
from randvib.identification.prediction import predict_record
from randvib.identification.record_integrator import FRICTION_PARAMETERS
from randvib.identification.record_response import record_response
from randvib.models.excitation import band_limited_excitation
from randvib.models.friction import FRICTION_MODELS
from randvib.models.parameters import parameter
from randvib.models.record import Record


@dataclass(frozen=True, eq=False)
class Stribeck(rv.FrictionModel):
    """Stribeck friction, F = (Fc + (Fs - Fc) exp(-(v/vs)^2)) s(v).

    Parameters
    ----------
    fc : float
        Coulomb (sliding) level Fc (N), >= 0.
    fs : float
        Static (breakaway) level Fs (N), >= 0.
    vs : float
        Stribeck velocity vs (m/s), > 0.
    vt : float
        Regularisation velocity (m/s), >= 0: s(v) = tanh(v/vt), or sgn(v)
        (sgn(0) = 0) for vt = 0. No default search bounds: fix it.
    """

    fc: float = parameter("N", search=lambda s: (1e-4 * s.force, s.force))
    fs: float = parameter("N", search=lambda s: (1e-4 * s.force, s.force))
    vs: float = parameter("m/s", positive=True, search=lambda s: (1e-4 * s.v_rms, 10 * s.v_rms))
    vt: float = parameter("m/s")

    name = "stribeck-test"

    def force(self, v, theta=None):
        v = np.asarray(v, dtype=float)
        level = self.fc + (self.fs - self.fc) * np.exp(-((v / self.vs) ** 2))
        vt = np.asarray(self.vt, dtype=float)
        shape = np.where(vt > 0, np.tanh(v / np.where(vt > 0, vt, 1.0)), np.sign(v))
        return level * shape

    @staticmethod
    def kernel(p, v, theta):
        ratio = v / p[2]
        level = p[0] + (p[1] - p[0]) * np.exp(-ratio * ratio)
        if p[3] > 0.0:
            return level * np.tanh(v / p[3]), 0.0
        if v > 0.0:
            return level, 0.0
        elif v < 0.0:
            return -level, 0.0
        return 0.0, 0.0


@numba.njit
def _call(callback, p, v, theta):
    return callback(p, v, theta)


FC = 0.0058  # N, paper Table 2 (Coulomb, training data 1)
DEVICE = rv.preset("figure9").updated(k3=5e5)  # c_m = c_e = 0.1 Ns/m, Duffing


def _with(friction):
    return DEVICE.updated(friction=friction)


def test_the_law_is_registered_everywhere_from_its_class():
    assert FRICTION_MODELS["stribeck-test"] is Stribeck
    assert "stribeck-test" in MODELS and "stribeck-test" in FRICTION_CHOICES
    assert FRICTION_PARAMETERS["stribeck-test"] == ("fc", "fs", "vs", "vt")
    law = Stribeck(FC, 2 * FC, 0.02, 0.0)
    # memoryless but not of the form Fc tanh(beta v): linearisation's alone, by the declarations
    accepting = [name for name, method in rv.METHODS.items() if method.accepts_friction(law)]
    assert accepting == ["linearisation", "bridge-closure"]  # the bridge's closure: any memoryless
    refusal = "form Fc tanh.*'stribeck-test' is not of that form: use method='linearisation' or"
    with pytest.raises(ValueError, match=refusal):
        rv.predict(_with(law), 0.5, "fpk-fast")
    # The compiled callback the loops call agrees with the numpy force.
    v = np.random.default_rng(0).normal(0.0, 0.05, 50)
    p = law.kernel_parameters()
    compiled = [_call(Stribeck.compiled_kernel(), p, x, 0.0)[0] for x in v]
    assert np.allclose(compiled, law.force(v), rtol=1e-14, atol=0)
    with pytest.raises(ValueError, match="`vs` must be > 0"):
        Stribeck(FC, FC, 0.0, 0.0)
    with pytest.raises(ValueError, match="not of that form"):
        rv.averaging_statistics(_with(law), 0.5)


def test_monte_carlo_through_the_callback_equals_the_inlined_coulomb_kernel():
    # Fs = Fc, vt = 0: F = Fc sgn v exactly (Fc + 0 * exp(...) rounds to Fc),
    # so the generic callback path must give the built-in path's numbers bit
    # for bit: same noise, same arithmetic.
    args = dict(psd=0.5, t_end=0.5, dt=1e-4, n_paths=16, burn_in=0.1, seed=3, check_step=False)
    own = rv.simulate(_with(Stribeck(FC, FC, 0.02, 0.0)), **args)
    builtin = rv.simulate(_with(rv.Coulomb(FC)), **args)
    for name in ("velocity_variance", "displacement_variance", "friction_power"):
        # Equal up to rounding only: the inlined force lets LLVM contract
        # c v + ... + F differently (FMA) from the call through the pointer.
        assert getattr(own, name).mean == pytest.approx(getattr(builtin, name).mean, rel=1e-9)


def energy_identity(seed, n_paths=64):
    """(result, c E[v^2] + E[vF] as a Statistic, S m / 4) for the Stribeck device."""
    psd = 0.5
    law = Stribeck(FC, 2.5 * FC, 0.03, 0.0)
    r = rv.simulate(
        _with(law),
        psd,
        t_end=4.0,
        dt=1e-4,
        n_paths=n_paths,
        burn_in=0.5,
        seed=seed,
        control_variates=True,
    )
    reference = psd * r.harvester.m / 4.0
    residual = r.energy_balance_residual()
    balance = type(residual)(
        mean=residual.mean + reference,
        ci95=residual.ci95,
        std_error=residual.std_error,
        n_paths=residual.n_paths,
    )
    return r, balance, reference


def test_monte_carlo_energy_identity_with_a_stribeck_peak():
    """c E[v^2] + E[v F] = S m / 4 for any memoryless friction (docs/conventions.md).

    Detects a 1 % error in the friction power or the velocity variance of the
    law's compiled force (e.g. a force evaluated at the wrong velocity); the
    residual's control variates (stored energy, Ito integral) make the
    ensemble small. Heun's step bias at dt = 1e-4 s is far below the
    threshold here (the Coulomb test in test_simulation.py bounds it at
    2e-3 of S m / 4). Calibration (tests/calibration/friction_family.py,
    seeds 100-139): z mean -0.29, SD 1.18, largest |z| 3.30; relative
    standard error 9.6e-4, so a 1 % bias is about 10 standard errors.
    """
    r, balance, reference = energy_identity(seed=5)
    assert_matches(balance, reference, detect=0.01, what="c E[v^2] + E[vF]")
    # The Stribeck peak dissipates more than Coulomb at the sliding level.
    assert r.friction_power.mean > FC * r.mean_abs_velocity.mean


def test_linearisation_reduces_to_eq30_and_matches_quadrature():
    psd = np.array([0.1, 0.5, 1.0])
    coulomb_like = _with(Stribeck(FC, FC, 0.02, 0.0))
    assert rv.equivalent_damping(coulomb_like, psd) == pytest.approx(
        rv.coulomb_equivalent_damping(DEVICE.c, FC, psd, DEVICE.m), rel=1e-10
    )
    with pytest.raises(ValueError, match="closed-form"):
        rv.equivalent_damping(coulomb_like, psd, expectation="closed-form")
    # E[v F(v)] of the law's numpy force against scipy's adaptive quadrature.
    law, sigma = Stribeck(FC, 3 * FC, 0.05, 0.0), 0.1

    def integrand(v):
        return v * float(law.force(v)) * np.exp(-(v**2) / (2 * sigma**2))

    exact = 2 * integrate.quad(integrand, 0, 40 * sigma, points=[0.05, 0.1], epsrel=1e-13)[0]
    exact /= np.sqrt(2 * np.pi) * sigma
    assert law.mean_velocity_force(sigma) == pytest.approx(exact, rel=1e-10)
    # The fixed point satisfies the linearised energy balance (Eq. 19-20).
    c_eq = rv.equivalent_damping(_with(law), 0.5)
    s2 = 0.5 * DEVICE.m / (4 * c_eq)
    assert DEVICE.c * s2 + law.mean_velocity_force(np.sqrt(s2)) == pytest.approx(
        0.5 * DEVICE.m / 4, rel=1e-10
    )


FS_REC = 500.0  # Hz
VT = 1e-3  # m/s: tanh(beta v) with beta = 1000 s/m, smooth on the RK4 step


@pytest.fixture(scope="module")
def drive():
    """A base acceleration record (m/s^2) at FS_REC."""
    motion = band_limited_excitation(2.0, FS_REC, 1.07, seed=0)
    return Record(motion.dt, base_acceleration=motion["base_acceleration"])


def test_record_simulation_reduces_to_the_builtin_tanh_law(drive):
    # Fs = Fc, vt > 0 is Tanh(Fc, 1/vt); at h = 2.5e-4 s < 2 m/(Fc beta) the
    # built-in law is integrated by the same RK4, so the two agree to rounding.
    own = record_response(_with(Stribeck(FC, FC, 0.02, VT)), drive, substeps=8).z[0]
    builtin = record_response(_with(rv.Tanh(FC, 1 / VT)), drive, substeps=8).z[0]
    assert np.max(np.abs(own - builtin)) <= 1e-9 * np.max(np.abs(builtin))


def test_record_response_simulates_the_total_damping(drive):
    """A record cannot separate c_m from c_e: a preset with both responds as the same
    device with their sum as c_m (0.25 + 0.125 is exact in binary)."""
    split = rv.preset("coulomb-td1").updated(c_m=0.25, c_e=0.125)
    total = rv.preset("coulomb-td1").updated(c_m=0.375, c_e=0.0)
    assert np.array_equal(record_response(split, drive).z, record_response(total, drive).z)


TRUE = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=FC, fs=2.0 * FC, vs=0.02, vt=VT)


def test_identification_recovers_the_law_from_a_noise_free_record(drive):
    """Noise-free record simulated with the law itself: the optimum is the truth.

    SaDE stops when the best cost changes by less than tol = 1e-6 (J is
    quadratic near the optimum, so parameters are then right to about
    sqrt(1e-6 / J'') relative, well inside 1 %); m (not identifiable under
    base excitation), k3 and the regularisation vt are fixed.
    """
    z = record_response(H.harvester(TRUE, "stribeck-test"), drive, substeps=8).z[0]
    record = Record(
        drive.dt, name="stribeck", base_acceleration=drive.input, relative_displacement=z
    )
    bounds = default_bounds(record, "stribeck-test", TRUE["m"])
    assert "vt" not in bounds  # declared without default bounds
    with pytest.raises(ValueError, match="declare no default search bounds"):
        identify(record, "stribeck-test", m=TRUE["m"], maxiter=1)
    res = identify(
        record,
        "stribeck-test",
        m=TRUE["m"],
        fixed={"k3": TRUE["k3"], "vt": VT},
        popsize=30,
        maxiter=150,
        seed=1,
        substeps=8,
    )
    assert res.cost < 1e-3
    for name in ("c", "k", "fc", "fs", "vs"):
        assert res.parameters[name] == pytest.approx(TRUE[name], rel=0.01), name
    # The identified device is a Harvester with this law, and predicts itself.
    device = res.harvester()
    assert isinstance(device.friction, Stribeck)
    assert predict_record(device, record, substeps=8).cost == pytest.approx(
        res.cost, rel=1e-6, abs=1e-9
    )
    assert res.to_dict()["units"]["vs"] == "m/s"
