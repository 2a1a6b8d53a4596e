"""An independent simulator of the rectified coil against the compiled bridge kernel.

Covers the bridge's step functions (:mod:`randvib.montecarlo.rectified_kernel`,
with the device's drift, :mod:`randvib.montecarlo.drift`) through
``randvib.simulate``. The reference below is written from the equations of
docs/conventions.md ("Full-wave bridge with a coil") in plain numpy and
shares no code, coefficient array or state layout with the package:

    m z'' + c_m z' + k z + k3 z^3 + F(z') + alpha i = -m a(t),
    i = sgn(e) max(0, |e| - V_out - 2 V_d) / R_C,  e = alpha z',
    V_out = V_b (battery) or V_C with C V_C' = |i| - V_C / R_L,

stored power V_b |i| (battery) or V_C^2 / R_L (capacitor), coil loss R_C i^2,
diode loss 2 V_d |i|. White input: a(t) is white with one-sided PSD S, the
velocity's diffusion sqrt(S/2). Band-pass input: a = 2 zeta w0 q' with
q'' + 2 zeta w0 q' + w0^2 q = sqrt(S/2) xi, whose one-sided PSD is
S (2 zeta f f0)^2 / ((f0^2 - f^2)^2 + (2 zeta f f0)^2) (docs/conventions.md).

Both are integrated by Euler-Maruyama and by stochastic Heun on the same
Brownian increments. Both schemes commute with any invertible linear change
of the filter's coordinates, so the package's filter realisation gives the
same paths up to round-off whatever states it uses: the comparison is pathwise, for the four
combinations of the issue's references (battery, capacitor + load; white,
band-pass), with Duffing stiffness and Coulomb friction, and covers every
switch of the bridge on the way (each path conducts and blocks many times,
asserted). The tolerance 1e-9 of each quantity's scale is round-off
accumulated over the path (the dead zone's current is Lipschitz in the state,
so a round-off difference cannot grow into a switching difference of finite
size), far below any modelling difference (a wrong sign, drop or output
voltage changes the paths at the percent level from the first conducting step).
"""

import warnings

import numpy as np
import pytest

import randvib as rv

M, C_M, K, K3, FC = 0.0226, 0.05, 57.4, 5e5, 0.005
ALPHA, R_COIL, V_D = 0.1992, 0.48, 0.01
S, F0, ZETA = 1.0, 8.0, 0.3
DT, N_STEPS, N_BURN, N_PATHS = 1e-4, 6000, 1000, 3
Z0, V0 = 0.001, 0.02

OUTPUTS = {
    "battery": dict(battery=0.03),
    "capacitor": dict(storage_capacitance=1e-2, r_load=10.0),
}


def reference(dw, output, band_pass, heun):
    """Independent paths (z, v) and window-averaged powers (W) of the bridge circuit.

    ``dw`` (n_paths, n_steps): Brownian increments (s^0.5). Euler-Maruyama,
    or stochastic Heun (``heun``: predictor X + f(X) dt + g dW, update
    X + (f(X) + f(X_p)) dt / 2 + g dW, additive noise). Returns z, v of shape
    (n_paths, n_steps + 1) and a dict of per-path mean powers over the steps
    from N_BURN on, each the scheme's own quadrature of the power (left point,
    or the mean of the two stages).
    """
    n_paths, n_steps = dw.shape
    battery = output.get("battery")
    cap, r_load = output.get("storage_capacitance"), output.get("r_load")
    w0 = 2.0 * np.pi * F0

    def rates(state):
        """Drift of (z, v, q, q', V_C) and the powers at a state (noise apart)."""
        z, v, q, qd, v_c = state
        v_out = battery if battery is not None else v_c
        e = ALPHA * v
        i = np.sign(e) * np.maximum(0.0, np.abs(e) - v_out - 2.0 * V_D) / R_COIL
        base = 2.0 * ZETA * w0 * qd if band_pass else 0.0
        acc = -(C_M * v + K * z + K3 * z**3 + FC * np.sign(v) + ALPHA * i) / M - base
        dv_c = (np.abs(i) - v_c / r_load) / cap if battery is None else 0.0 * v_c
        drift = np.array([v, acc, qd, -(w0**2) * q - 2.0 * ZETA * w0 * qd, dv_c])
        powers = {
            "stored": battery * np.abs(i) if battery is not None else v_c**2 / r_load,
            "coil": R_COIL * i**2,
            "diode": 2.0 * V_D * np.abs(i),
            "conducting": (i != 0.0).astype(float),
        }
        return drift, powers

    # the noise enters the velocity (white) or the filter's rate (band-pass)
    g = np.zeros((5, 1))
    g[3 if band_pass else 1] = np.sqrt(S / 2.0)
    x = np.zeros((5, n_paths))  # (z, v, q, q', V_C): filter at rest, capacitor empty
    x[0], x[1] = Z0, V0
    zs, vs = [x[0].copy()], [x[1].copy()]
    sums = {k: np.zeros(n_paths) for k in ("stored", "coil", "diode", "conducting")}
    for n in range(n_steps):
        noise = g * dw[:, n]
        f1, p1 = rates(x)
        if heun:
            f2, p2 = rates(x + f1 * DT + noise)
            x = x + 0.5 * (f1 + f2) * DT + noise
            stage = {k: 0.5 * (p1[k] + p2[k]) for k in p1}
        else:
            x = x + f1 * DT + noise
            stage = p1
        if n >= N_BURN:
            for k in sums:
                sums[k] += stage[k]
        zs.append(x[0].copy())
        vs.append(x[1].copy())
    window = n_steps - N_BURN
    return np.array(zs).T, np.array(vs).T, {k: s / window for k, s in sums.items()}


@pytest.mark.parametrize("scheme", ["euler-maruyama", "heun"])
@pytest.mark.parametrize("band_pass", [False, True], ids=["white", "band-pass"])
@pytest.mark.parametrize("output", list(OUTPUTS))
def test_kernel_paths_and_powers_equal_the_independent_simulator(output, band_pass, scheme):
    dw = np.random.default_rng(21).normal(0.0, np.sqrt(DT), (N_PATHS, N_STEPS))
    coupling = rv.BridgeCoil(ALPHA, R_COIL, v_diode=V_D, **OUTPUTS[output])
    h = rv.Harvester.with_coupling(M, C_M, K, coupling, k3=K3, friction=rv.Coulomb(FC))
    excitation = rv.BandPass(S, F0, ZETA) if band_pass else S
    with warnings.catch_warnings():  # a start from a given state and a short burn-in, on purpose
        warnings.simplefilter("ignore")
        r = rv.simulate(
            h, excitation, t_end=N_STEPS * DT, burn_in=N_BURN * DT, dt=DT, n_paths=N_PATHS,
            dW=dw, initial=(Z0, V0), scheme=scheme, record_paths=N_PATHS,
            record_every=1, check_step=False, progress=False,
        )  # fmt: skip
    z, v, powers = reference(dw, OUTPUTS[output], band_pass, scheme == "heun")
    # the paths conduct and block: the comparison covers the bridge's switching
    assert np.all((powers["conducting"] > 0.05) & (powers["conducting"] < 0.95)), powers
    for name, ours, theirs in (("z", r.histories.z, z), ("v", r.histories.v, v)):
        scale = np.max(np.abs(theirs))
        assert np.max(np.abs(ours - theirs)) <= 1e-9 * scale, name
    a = r.averages
    for name, ours in (("stored", a.stored_power), ("coil", a.coil_loss), ("diode", a.diode_loss)):
        np.testing.assert_allclose(ours, powers[name], rtol=1e-9, err_msg=name)
    assert np.all(powers["stored"] > 0.0)
