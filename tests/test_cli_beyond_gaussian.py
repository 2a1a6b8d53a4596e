"""``randvib power`` and ``simulate`` with tones, non-Gaussian input and shocks.

The CLI runs what the Python API runs: ``--tone``, ``--kurtosis`` and the
``--shock-*`` options build the input that :func:`randvib.predict` and
:func:`randvib.simulate` take (the same JSON, bit for bit, for the same seed),
the existing JSON keys keep their meaning (``excitation`` holds the spectrum's
keys, with ``tones`` and ``shocks`` beside them), a ``--marginal`` table or
record builds the translation's marginal, and every refusal is one line
naming the flag and what is allowed (exit 2).

Covers the options of :mod:`randvib.cli._excitation` beyond the spectrum
(:func:`randvib.models.tone.parse_tone`).
"""

import json

import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv

DUFFING = ["--preset", "figure9", "--k3", "5e5"]  # Coulomb friction, Duffing spring
BAND = ["--excitation", "band-pass", "--psd", "1", "--f0", "8", "--zeta", "0.1"]
SIM = ["--paths", "16", "--t-end", "1.0", "--burn-in", "0.5", "--dt", "2.5e-4", "--no-progress"]


def _json(capsys, *argv):
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    return json.loads(out)


def test_power_under_a_tone_on_band_pass_noise_is_the_api_s(capsys):
    out = _json(capsys, "power", *DUFFING, *BAND, "--tone", "8:1", "--tone", "20:0.5:45")
    x = rv.BandPass(1.0, 8.0, 0.1) + rv.Tone(8.0, 1.0) + rv.Tone(20.0, 0.5, 45.0)
    api = rv.predict(rv.preset("figure9").updated(k3=5e5), x)
    assert out["power_electrical"] == api.power_electrical
    assert out["psd"] == 1.0 and out["method"] == "linearisation"
    assert out["excitation"]["excitation"] == "band-pass" and out["excitation"]["f0"] == 8.0
    assert out["excitation"]["tones"][1] == {"frequency": 20.0, "amplitude": 0.5, "phase": 45.0}
    assert [t["displacement_amplitude"] for t in out["tones"]] == [
        t.displacement_amplitude for t in api.tones
    ]


def test_simulate_under_a_tone_on_band_pass_noise_is_the_api_s(capsys):
    out = _json(capsys, "simulate", *DUFFING, *BAND, "--tone", "8:1", *SIM)
    x = rv.BandPass(1.0, 8.0, 0.1) + rv.Tone(8.0, 1.0)
    api = rv.simulate(rv.preset("figure9").updated(k3=5e5), x, t_end=1.0, burn_in=0.5, dt=2.5e-4,
                      n_paths=16, seed=0, progress=False).summary()  # fmt: skip
    assert out["power_electrical"] == json.loads(json.dumps(api["power_electrical"]))


def test_kurtosis_6_through_power_and_simulate(capsys):
    code, out, err = run(capsys, "power", *DUFFING, *BAND, "--kurtosis", "6", "--json")
    assert code == 0 and "kurtosis 6" in err  # the Gaussian answer's warning, one line
    power = json.loads(out)
    assert power["excitation"]["excitation"] == "translated"
    assert power["excitation"]["kurtosis"] == pytest.approx(6.0, rel=1e-3)
    assert power["excitation"]["level"] == 1.0 and power["excitation"]["spectrum"] == "band-pass"
    sim = _json(capsys, "simulate", *DUFFING, *BAND, "--kurtosis", "6", *SIM)
    x = rv.Translated(rv.BandPass(1.0, 8.0, 0.1), 6.0)
    api = rv.simulate(rv.preset("figure9").updated(k3=5e5), x, t_end=1.0, burn_in=0.5, dt=2.5e-4,
                      n_paths=16, seed=0, progress=False).summary()  # fmt: skip
    assert sim["power_electrical"] == json.loads(json.dumps(api["power_electrical"]))


def test_shocks_alone_on_a_linear_device_give_campbell_s_power(capsys):
    shocks = ["--shock-rate", "2", "--shock-amplitude", "20", "--shock-duration", "0.01"]
    out = _json(capsys, "power", "--preset", "figure9", "--fc", "0", "--k3", "0", "--psd", "0",
                *shocks, "--shock-shape", "rectangular")  # fmt: skip
    train = rv.ShockTrain(2.0, 20.0, 0.01, shape="rectangular")
    linear = rv.preset("figure9").updated(fc=0.0, k3=0.0)
    assert out["power_electrical"] == rv.predict(linear, train).power_electrical
    assert out["excitation"] == {"excitation": "none", "shocks": train.parameters()}


def test_a_marginal_table_and_a_record_s_samples(capsys, tmp_path):
    x = np.linspace(-30.0, 30.0, 3001)  # a table cut at 8 would lose 10 % of E[x^4]
    table = tmp_path / "laplace.csv"
    table.write_text("value,density\n" + "\n".join(f"{v},{0.5 * np.exp(-abs(v))}" for v in x))
    out = _json(capsys, "power", *DUFFING, *BAND, "--marginal", table)
    assert out["excitation"]["marginal"] == "table"
    assert out["excitation"]["kurtosis"] == pytest.approx(6.0, rel=0.05)
    record = tmp_path / "record.csv"
    samples = np.random.default_rng(0).laplace(0.0, 1.0, 4096)
    record.write_text("base_acceleration\n" + "\n".join(f"{v}" for v in samples))
    out = _json(capsys, "power", *DUFFING, *BAND, "--marginal", record)
    assert (
        out["excitation"]["marginal"] == "samples" and out["excitation"]["marginal_samples"] == 4096
    )


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["power", *BAND, "--tone", "8"], "`--tone` must be F:A or F:A:PHASE"),
        (["power", *BAND, "--tone", "8:-1"], "`--tone` '8:-1': A must be > 0 (in m/s^2)"),
        (["power", *BAND, "--kurtosis", "1.5"], "`--kurtosis` must be > 1.8"),
        (["power", "--psd", "1", "--kurtosis", "6"], "`--kurtosis` needs a spectrum of finite variance"),
        (["power", *BAND, "--kurtosis", "6", "--marginal", "x.csv"], "give one of `--kurtosis` and `--marginal`"),
        (["power", "--psd", "1", "--shock-rate", "2"], "`--shock-rate` describes a shock train, which also needs `--shock-amplitude` and `--shock-duration`"),
        (["power", "--psd", "1", "--shock-rate", "2", "--shock-amplitude", "1", "--shock-duration", "-1"], "`--shock-duration` must be > 0 (in s)"),
        (["power", "--preset", "figure9", "--psd", "0", "--shock-rate", "2", "--shock-amplitude", "1", "--shock-duration", "0.01"], "treats shocks on a linear device only"),
        (["power", "--preset", "figure9", "--psd", "0", "--tone", "8:1", "--method", "fpk-fast"], "`--method fpk-fast` treats random input only; the tones (8 Hz) need `--method linearisation`"),
        (["simulate", "--psd", "1", "--tone", "3000:1", *SIM], "the tone at 3000 Hz (`--tone`) is at or above the simulation's Nyquist frequency 2000 Hz"),
        (["simulate", "--psd", "1", "--tone", "8:1", "--control-variates", *SIM], "`--control-variates` needs Gaussian noise alone"),
    ],
)  # fmt: skip
def test_refusals_are_one_line_naming_the_flag(capsys, argv, fragment):
    if "--preset" not in argv:
        argv = [argv[0], "--preset", "figure9", *argv[1:]]
    one_line_error(capsys, argv, fragment)
