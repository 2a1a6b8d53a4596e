"""The record simulation behind a full-wave diode bridge, and identification from its DC side.

Covers :mod:`randvib.identification.record_bridge` (the Monte Carlo kernel's
bridge step driven by a recorded input, checked step for step against that
kernel on the same increments), its use by ``record_response``,
``randvib record --rectifier bridge``, ``validate`` (:mod:`randvib.identification.prediction`)
and ``identify(rectifier=...)`` /
``randvib identify --rectifier bridge``, against the independent plain-numpy
RK4 integrator of ``tests/_bridge_reference.py``.

Tolerances: the record simulation's pathwise error at 8 sub-steps is bounded by
its change from 4 to 8 sub-steps (for a scheme of order p >= 1 the error of the
finer run is about that change / (2^p - 1), at most the change), plus the
reference's own error (RK4 at 32 steps per sample against 64, measured by
``python tests/test_record_bridge.py``); identified parameters within 4 standard
errors of the truth (the suite's false-failure rate of about 6e-5 per assertion
for a correct interval).
"""

import json

import _bridge_reference as B
import _electrical as E
import numpy as np
import pandas as pd
import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.identification.prediction import validate
from randvib.models.record import Record

FS = 1000.0
#: The paper's mechanics with a coil strong enough to pass the diodes' drops.
MECHANICS = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0)
STORAGE = dict(MECHANICS, alpha=1.0, r_coil=2.0, v_diode=0.2, storage_capacitance=2e-3,
               r_load=50.0)  # fmt: skip
BATTERY = dict(MECHANICS, alpha=1.0, r_coil=2.0, v_diode=0.1, battery=0.1)
#: With the coil's inductance: its current a state, held at 0 by the diodes.
INDUCTIVE = dict(STORAGE, inductance=0.02)


def bridged(device):
    """The Harvester of a dict of :data:`STORAGE`'s or :data:`BATTERY`'s form."""
    electrical = {k: v for k, v in device.items() if k not in MECHANICS}
    bridge = rv.BridgeCoil(**electrical)
    return rv.Harvester.with_coupling(
        device["m"], device["c"], device["k"], bridge, k3=device["k3"]
    )


def relative_rms(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.std(b))


@pytest.mark.parametrize(
    "device, kind, column, reference_error",
    [(STORAGE, "voltage", 3, 2e-7), (BATTERY, "current", 2, 1e-7), (INDUCTIVE, "voltage", 3, 3e-6)],
    ids=["storage-voltage", "battery-current", "inductance-storage-voltage"],
)  # fmt: skip
def test_bridge_record_matches_an_independent_rk4_within_its_step_error(
    device, kind, column, reference_error
):
    """A coil behind a bridge (L = 0: the dead-zone current; L > 0: the current a state
    the diodes hold at 0), its DC output voltage V_C or its charging current |i| against
    plain RK4 on the same linearly interpolated input. The error at 8 sub-steps is at
    most its change from 4 to 8 (order >= 1) plus the reference's own (RK4 at 32 against
    64 steps per sample: 1.6e-7, 8.1e-8 and 1.9e-6 of the RMS, ``python
    tests/test_record_bridge.py``); measured second order (the storage voltage 4.9e-4 at
    4 sub-steps, 1.2e-4 at 8, 3.1e-5 at 16; with L: 5.1e-4, 1.4e-4, 3.3e-5), hence the
    ratio > 3. A diode drop counted once instead of twice moves V_C by about 10 % of its
    RMS."""
    a = E.base_acceleration(1.0, FS, 4.0, 3)
    reference = B.coil_bridge_states(device, a, FS, up=32)
    truth = np.abs(reference[:, column]) if kind == "current" else reference[:, column]
    drive = Record(1.0 / FS, base_acceleration=a)
    runs = {n: rv.record_response(bridged(device), drive, substeps=n) for n in (4, 8)}
    y4, y8 = (runs[n].output(kind)[0] for n in (4, 8))
    assert np.std(truth) > 0  # the bridge conducts
    change = relative_rms(y4, y8) * np.std(y8) / np.std(truth)
    error = relative_rms(y8, truth)
    assert error <= change + reference_error, (error, change)
    assert relative_rms(y4, truth) / error > 3.0  # second order: 4 in the limit
    assert relative_rms(runs[8].z[0], reference[:, 0]) <= 1e-3


def test_bridge_record_is_the_monte_carlo_kernels_bridge_on_the_same_increments():
    """White noise given as a force record (u = m sqrt(S/2) dW / dt, zero-order hold, one
    sub-step) makes the record simulation take the Monte Carlo kernel's Heun steps on the
    same increments: each path's time average of the storage voltage (the kernel's
    output-voltage accumulator, V_C at each step's start) is the record's mean V_C over the
    same samples, to rounding. A wrong sign or scale of the input, or another step, would
    move it by the ratio of the responses."""
    device, psd, dt, n = bridged(STORAGE), 5.0, 5e-4, 4000
    dw = np.random.default_rng([7, 34]).normal(0.0, np.sqrt(dt), (2, n))
    with pytest.warns(RuntimeWarning, match="starts empty"):  # as the record's: from rest
        mc = rv.simulate(
            device, psd, t_end=n * dt, dt=dt, n_paths=2, dW=dw, initial="rest", burn_in=0.0,
            scheme="heun", check_step=False, progress=False,
        )  # fmt: skip
    for path in range(2):
        force = np.append(STORAGE["m"] * np.sqrt(psd / 2) * dw[path] / dt, 0.0)
        sim = rv.record_response(device, Record(dt, force=force), substeps=1, hold="zero")
        v_c = sim.output("voltage")[0]
        assert v_c.max() > 0.05  # the bridge conducted
        assert np.mean(v_c[:-1]) == pytest.approx(mc.averages.output_voltage[path], rel=1e-9)
    with pytest.raises(ValueError, match="`substeps` = 1 leaves a step of 0.002 s"):
        rv.record_response(device, Record(2e-3, force=force[::4]), substeps=1)


def test_piezo_bridge_record_keeps_its_clamp_and_refuses_a_constant_channel():
    """A piezo element into a storage capacitor: its voltage never exceeds the bridge's
    threshold V_C + 2 V_d (the clamp) and V_C stays >= 0 and charges; a battery's voltage
    channel (its constant V_b) and a piezo's current into a battery are refused."""
    bridge = rv.BridgePiezo(theta=5e-4, capacitance=1e-7, v_diode=0.2,
                            storage_capacitance=1e-6, r_load=1e5)  # fmt: skip
    device = rv.Harvester.with_coupling(0.01, 0.01, 100.0, bridge, k3=2e6)
    drive = Record(1.0 / FS, base_acceleration=E.base_acceleration(1.0, FS, 4.0, 1))
    sim = rv.record_response(device, drive)
    v_c = sim.output("voltage")[0]
    assert np.all(np.abs(sim.x[0]) <= v_c + 2 * 0.2 + 1e-12)
    assert np.all(v_c >= 0) and v_c.max() > 0.1
    assert np.allclose(sim.output("current")[0], v_c / 1e5)
    battery = rv.Harvester.with_coupling(
        0.01, 0.01, 100.0, rv.BridgePiezo(theta=5e-4, capacitance=1e-7, battery=0.5), k3=2e6
    )
    sim = rv.record_response(battery, drive)
    with pytest.raises(ValueError, match="constant and fixes nothing"):
        sim.output("voltage")
    with pytest.raises(ValueError, match="clamp's jumps"):
        sim.output("current")


def storage_record(seed=3, noise=0.01, duration=2.0):
    """The DC voltage of :data:`STORAGE` from the reference, with sensor noise (share of RMS)."""
    a = E.base_acceleration(duration, FS, 4.0, seed)
    volts = B.coil_bridge_states(STORAGE, a, FS, up=16)[:, 3]
    rng = np.random.default_rng([seed, 35])
    measured = volts + noise * np.std(volts) * rng.standard_normal(volts.size)
    return Record(1.0 / FS, base_acceleration=a, voltage=measured, name="bridge")


def test_bridge_dc_voltage_identifies_damping_stiffness_and_coupling_within_intervals():
    """c_m, k and alpha from the storage capacitor's voltage alone (1 % sensor noise, one
    load, the mass, R_C, k3 and the bridge known): each within 4 standard errors; the
    threshold V_C + 2 V_d fixes alpha's scale, so c_m and alpha split at one load (a
    linear coil's voltage would not split them). J is the noise's 100 x 0.01^2 to within
    4 chi-squared spreads of 2000 samples (4 x 3.2 %)."""
    start = {k: STORAGE[k] * 1.05 for k in ("c", "k", "alpha")}
    init = rv.Harvester.with_coupling(
        STORAGE["m"], start["c"], start["k"], rv.Inductive(start["alpha"], 50.0, 2.0, 0.0),
        k3=STORAGE["k3"],
    )  # fmt: skip
    fit = rv.identify(
        storage_record(), "viscous", m=STORAGE["m"], coupling="inductive", r_load=50.0,
        rectifier={"v_diode": 0.2, "storage_capacitance": 2e-3}, outputs=("voltage",),
        fixed={"k3": STORAGE["k3"], "r_coil": 2.0, "inductance": 0.0, "voltage_offset": 0.0},
        bounds={"k": (20.0, 200.0)}, popsize=8, maxiter=3, seed=1, progress=False, init=init,
    )  # fmt: skip
    for name in ("c", "k", "alpha"):
        z = (fit.parameters[name] - STORAGE[name]) / fit.standard_errors[name]
        assert abs(z) <= 4.0, (name, z)
    assert fit.cost == pytest.approx(100 * 0.01**2, rel=4 * 0.032)
    assert any("diode bridge" in r for r in fit.identifiability.reasons)
    assert any("v_diode = 0.2" in n for n in fit.notes)


def test_validate_scores_the_dc_voltage_of_a_device_behind_a_bridge():
    """``validate`` of the true device on its DC voltage record (1 % sensor noise): J
    is the noise's 100 x 0.01^2 to within 4 chi-squared spreads of 2000 samples, the RMS
    error 1 % of the voltage's RMS to within 4 x 1.6 %; alpha 5 % high misses by far more."""
    record = storage_record()
    (row,) = validate(bridged(STORAGE), [record], outputs=("voltage",), offsets="given")
    assert row.channels["voltage"]["cost"] == pytest.approx(100 * 0.01**2, rel=4 * 0.032)
    scale = 0.01 * np.std(record["voltage"])
    assert row.rms_error == pytest.approx(scale, rel=4 * 0.016)
    (wrong,) = validate(
        bridged({**STORAGE, "alpha": 1.05}), [record], outputs=("voltage",), offsets="given"
    )
    assert wrong.cost > 10 * row.cost


def record_flags(out, *extra):
    s = STORAGE
    return ["record", "--m", s["m"], "--c-m", s["c"], "--k", s["k"], "--k3", s["k3"],
            "--coupling", "inductive", "--alpha", s["alpha"], "--r-coil", s["r_coil"],
            "--rectifier", "bridge", "--v-diode", s["v_diode"],
            "--rms", "4", "--duration", "2", "--seed", "3", "--out", out, *extra]  # fmt: skip


def test_record_and_identify_behind_a_bridge_from_the_command_line(tmp_path, capsys):
    """``randvib record --rectifier bridge`` writes the DC voltage as simulated (the
    record simulation's, read back exactly), and ``randvib identify --rectifier bridge``
    recovers alpha from it within 4 standard errors."""
    out = tmp_path / "bridge.csv"
    flags = record_flags(out, "--storage-capacitance", STORAGE["storage_capacitance"],
                         "--r-load", STORAGE["r_load"], "--output-kind", "voltage",
                         "--noise", "voltage=0.002")  # fmt: skip
    code, _, err = run(capsys, *flags)
    assert code == 0, err
    saved = json.loads(out.with_suffix(".json").read_text())
    assert saved["outputs"] == ["voltage"] and saved["device"]["v_diode"] == 0.2
    columns = pd.read_csv(out)
    assert list(columns) == ["time", "base_acceleration", "voltage"]
    assert columns["voltage"].mean() > 0.05  # the capacitor charged
    code, text, err = run(
        capsys, "identify", out, "--model", "viscous", "--m", STORAGE["m"], "--coupling",
        "inductive", "--r-load", "50", "--rectifier", "bridge", "--v-diode", "0.2",
        "--storage-capacitance", "2e-3", "--output-kind", "voltage", "--fix", "k3=70742",
        "--fix", "r_coil=2", "--fix", "inductance=0", "--fix", "voltage_offset=0",
        "--bounds", "k=20:200", "--bounds", "alpha=0.5:2", "--bounds", "c=0.01:0.2",
        "--popsize", "12", "--generations", "8", "--no-progress", "--json",
    )  # fmt: skip
    assert code == 0, err
    fit = json.loads(text)
    z = (fit["parameters"]["alpha"] - 1.0) / fit["standard_errors"]["alpha"]
    assert abs(z) <= 4.0, (fit["parameters"], fit["standard_errors"])


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--storage-capacitance", "2e-3", "--r-load", "50", "--output-kind", "voltage",
          "--coupling", "piezo"], "--alpha"),
        (["--battery", "0.1", "--output-kind", "voltage"], "voltage"),
    ],
    ids=["foreign-coupling-option", "battery-voltage"],
)  # fmt: skip
def test_record_refuses_what_a_bridge_cannot_give(tmp_path, capsys, argv, fragment):
    """A battery's constant voltage channel, and a bridge's options on the wrong
    transducer, exit 2 with one line naming what is wrong."""
    one_line_error(capsys, record_flags(tmp_path / "r.csv", *argv), fragment)


def test_identify_refuses_a_bridge_without_its_coupling_or_its_flag(tmp_path, capsys):
    """``--v-diode`` without ``--rectifier bridge``, the bridge without ``--coupling`` or on
    a resistive coupling, and a bridge without its output: one line each, naming the flag."""
    path = tmp_path / "r.csv"
    Record(1e-3, base_acceleration=np.sin(np.arange(100) / 5.0),
           voltage=np.cos(np.arange(100) / 5.0)).to_frame().to_csv(path, index=False)  # fmt: skip
    base = ["identify", path, "--model", "viscous", "--m", "0.02", "--output-kind", "voltage",
            "--no-progress"]  # fmt: skip
    one_line_error(capsys, [*base, "--v-diode", "0.2"], "`--v-diode` needs `--rectifier bridge`")
    one_line_error(capsys, [*base, "--rectifier", "bridge"], "coupling")
    one_line_error(
        capsys, [*base, "--rectifier", "bridge", "--coupling", "resistive", "--r-load", "5",
                 "--storage-capacitance", "1e-3"], "'inductive' or 'piezo'",
    )  # fmt: skip
    one_line_error(
        capsys,
        [*base, "--rectifier", "bridge", "--coupling", "inductive", "--r-load", "5"],
        "exactly one output",
    )


if __name__ == "__main__":  # the reference's own error, quoted in the module docstring
    a = E.base_acceleration(1.0, FS, 4.0, 3)
    for device, column in ((STORAGE, 3), (BATTERY, 2), (INDUCTIVE, 3)):
        coarse, fine = (B.coil_bridge_states(device, a, FS, up=u) for u in (32, 64))
        scale = np.std(np.abs(fine[:, column]))
        print(column, float(np.sqrt(np.mean((coarse[:, column] - fine[:, column]) ** 2))) / scale)
