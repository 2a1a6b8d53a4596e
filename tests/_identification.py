"""Synthetic records and the linearised least-squares error model for identification tests.

Shared by ``tests/test_identification.py`` and the seed study
``tests/calibration/identification.py``.

The error model is :class:`Linearisation`: sensitivities of the simulated
response are central differences of :func:`randvib.identification.record_response.record_response`
(one batched call), and the initial state ``identify`` starts from (first
sample, fourth-order one-sided velocity :data:`VELOCITY_STENCIL`) is
re-implemented here, so the reference does not go through
:mod:`randvib.identification.cost`.
"""

from __future__ import annotations

import numpy as np

from randvib.identification.models import MeasurementModel, check_model
from randvib.identification.record_response import record_response
from randvib.models.excitation import band_limited_excitation
from randvib.models.harvester import Harvester
from randvib.models.record import Record

#: Paper Table 2, Coulomb model, training data 1 (m from docs/conventions.md).
COULOMB = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058)
#: Fourth-order one-sided first derivative at the first sample, times 12 dt.
VELOCITY_STENCIL = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0
#: Relative finite-difference step of the sensitivities.
STEP = 1e-4


def excitation(seed, duration, fs, rms=1.07):
    return band_limited_excitation(duration, fs, rms, seed=seed)


def harvester(params, model="coulomb"):
    """The device of identify's named parameters (``c`` as c_m), unchecked: scalars or
    1-D arrays (a batch). ``model``: an identification model (``viscous``: no friction)."""
    law = check_model(model)
    friction = None if law is None else law(**{n: params[n] for n in law.parameter_names()})
    return Harvester(
        m=params["m"], c_m=params["c"], c_e=0.0, k=params["k"], k3=params["k3"], friction=friction
    )


def measurement(params):
    """The measurement model among named parameters (k2 and the offsets; absent ones 0)."""
    return MeasurementModel.from_parameters(params)


def clean_response(params, model, ex, *, z0=0.0, v0=0.0, substeps=8):
    """Noise-free relative displacement and velocity driven by the exact base acceleration."""
    sim = record_response(
        harvester(params, model), ex, input_kind="base_acceleration", substeps=substeps, z0=z0,
        v0=v0,
    )  # fmt: skip
    return sim.z[0], sim.v[0]


def make_record(ex, z, *, kind="base_acceleration", noise=0.0, noise_seed=None, name="synthetic"):
    """Record of ``z`` (plus white noise of standard deviation ``noise`` m) and the base input."""
    if noise:
        z = z + noise * np.random.default_rng(noise_seed).standard_normal(z.size)
    return Record(ex.dt, name=name, relative_displacement=z, **{kind: ex[kind]})


def initial_state(z, dt):
    """The initial state identify starts from: first sample and the stencil's velocity."""
    return float(z[0]), float(VELOCITY_STENCIL @ z[:5] / dt)


def sensitivities(params, model, record, free, z0, v0, *, substeps=4):
    """``zhat`` at ``params`` and its derivatives by central differences, in one batched call.

    Returns ``zhat`` (n,), ``S`` (n x len(free), per unit log-parameter),
    ``s_z`` and ``s_v`` (n,). The record's own input is used, so a
    base-displacement record is driven through the package's differentiation
    exactly as in ``identify``.
    """
    names = list(free) + ["z0", "v0"]
    rows = 2 * len(names) + 1
    batch = {k: np.full(rows, float(v)) for k, v in params.items()}
    z0s = np.full(rows, float(z0))
    v0s = np.full(rows, float(v0))
    scale_z = np.std(record.z)
    scale_v = np.std(np.diff(record.z)) / record.dt
    steps = []
    for j, name in enumerate(names):
        h = {"z0": STEP * scale_z, "v0": STEP * scale_v}.get(name, STEP)
        for s, sign in enumerate((1.0, -1.0)):
            row = 2 * j + s
            if name == "z0":
                z0s[row] += sign * h
            elif name == "v0":
                v0s[row] += sign * h
            else:
                batch[name][row] *= np.exp(sign * h)
        steps.append(h)
    z = record_response(harvester(batch, model), record, substeps=substeps, z0=z0s, v0=v0s).z
    d = (z[0:-1:2] - z[1::2]) / (2 * np.array(steps)[:, None])
    return z[-1], d[:-2].T, d[-2], d[-1]


class Linearisation:
    """Least squares around the truth: the offset of the optimum and its noise response.

    ``clean`` is the noise-free record, ``free`` the identified parameters
    and ``skip`` the samples left out of J. With ``S`` the sensitivities at
    ``params`` (started, like ``identify``, from the record's first sample
    and stencil velocity) and ``P = (S'S)^-1 S'`` over the scored samples:

    * ``bias = P (z_clean - zhat)``: the Gauss-Newton step from the truth on
      the noise-free record. It contains every deterministic mismatch (the
      initial-velocity stencil's truncation error, the integration step, a
      differentiated base displacement) and is where a converged optimiser
      must land.
    * white noise ``eps`` on the scored samples moves ``ln theta`` by
      ``P eps``: standard errors ``sigma sqrt(diag(P P'))``;
    * noise on the first five samples moves the initial state identify starts
      from; its effect is computed exactly (nonlinear in the state) by
      :meth:`initial_state_shift`. It cannot be treated as a small
      perturbation: with Coulomb friction a velocity error of a few per cent
      of the RMS velocity changes the stick-slip history, and its effect on
      the fit is tens of times what the derivative ``d zhat / d v0`` predicts.
    """

    def __init__(self, params, model, clean, free, *, skip=0):
        self.params, self.model, self.clean, self.free, self.skip = (
            params, model, clean, tuple(free), skip,
        )  # fmt: skip
        self.z0, self.v0 = initial_state(clean.z, clean.dt)
        self.zhat, S, _, _ = sensitivities(params, model, clean, self.free, self.z0, self.v0)
        self.P = np.linalg.solve(S[skip:].T @ S[skip:], S[skip:].T)
        self.bias = self.P @ (clean.z - self.zhat)[skip:]

    def standard_errors(self, sigma):
        """Standard errors of ``ln theta`` for white noise ``sigma`` on the scored samples."""
        assert self.skip >= 5, "the stencil's samples must not be scored"
        return sigma * np.sqrt(np.sum(self.P**2, axis=1))

    def initial_state_shift(self, record):
        """Change of ``ln theta`` caused by starting from ``record``'s initial state."""
        z0, v0 = initial_state(record.z, record.dt)
        zhat = sensitivities(self.params, self.model, self.clean, (), z0, v0)[0]
        return self.P @ (self.zhat - zhat)[self.skip :]


def smoothstep(x):
    """C3 ramp from 0 (x <= 0) to 1 (x >= 1) and its first two derivatives."""
    x = np.clip(x, 0.0, 1.0)
    s = x**4 * (35 - 84 * x + 70 * x**2 - 20 * x**3)
    ds = 140 * x**3 * (1 - x) ** 3
    d2s = 420 * x**2 * (1 - x) ** 2 * (1 - 2 * x)
    return s, ds, d2s


def tapered(ex, ramp=0.2):
    """The excitation faded in and out over ``ramp`` s: a shaker starting and ending at rest.

    Returns the displacement ``w y`` and its exact second derivative
    ``w'' y + 2 w' y' + w y''`` (``y`` and its derivatives are exact spectral
    integrals). The base is at rest, to third order, at both ends of the
    record, so the second-order stencils that
    :func:`randvib.identification.input_reconstruction.second_derivative` uses next to the ends see
    no motion, and the differentiated displacement carries only the interior
    stencil's error (omega dt)^4 / 90.
    """
    t = ex.time
    T = t[-1]
    a, da, d2a = smoothstep(t / ramp)
    b, db, d2b = smoothstep((T - t) / ramp)
    w = a * b
    dw = (da * b - a * db) / ramp
    d2w = (d2a * b - 2 * da * db + a * d2b) / ramp**2
    y = w * ex["base_displacement"]
    acc = d2w * ex["base_displacement"] + 2 * dw * ex["base_velocity"] + w * ex["base_acceleration"]
    return y, acc


# ------------------------------------------------------------- the noisy-record study
#: Noisy Coulomb record: excitation seed, length (s), rate (Hz), noise (m), samples skipped.
NOISY = dict(seed=0, duration=3.0, fs=500.0, sigma=1e-6, skip=500)
FREE = ("c", "k", "k3", "fc")


def noisy_coulomb_record(noise_seed):
    """The noise-free and the noisy record of :data:`NOISY` (noise seeded by ``noise_seed``)."""
    ex = excitation(NOISY["seed"], NOISY["duration"], NOISY["fs"])
    z, _ = clean_response(COULOMB, "coulomb", ex)
    clean = make_record(ex, z, name="clean")
    noisy = make_record(ex, z, noise=NOISY["sigma"], noise_seed=noise_seed, name="noisy")
    return clean, noisy


def noisy_coulomb_z(noise_seed, lin=None):
    """z-scores of the identified ``ln theta`` on the noisy record of :data:`NOISY`.

    ``z = (ln theta_hat - ln theta - bias - initial-state shift) / SE``; ``lin``
    (the record's :class:`Linearisation`) may be passed to reuse it. Returns
    the fit, the z-scores and the standard errors.
    """
    from randvib.identification.identify import identify

    clean, noisy = noisy_coulomb_record(noise_seed)
    if lin is None:
        lin = Linearisation(COULOMB, "coulomb", clean, FREE, skip=NOISY["skip"])
    res = identify(
        noisy, "coulomb", m=COULOMB["m"], popsize=30, maxiter=80, seed=1, skip=NOISY["skip"],
        fixed={"input_offset": 0.0, "output_offset": 0.0}, initial_state="record",
    )  # fmt: skip
    err = np.array([np.log(res.parameters[n] / COULOMB[n]) for n in FREE])
    se = lin.standard_errors(NOISY["sigma"])
    return res, (err - lin.bias - lin.initial_state_shift(noisy)) / se, se
