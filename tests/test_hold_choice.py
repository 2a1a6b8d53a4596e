"""The input's reconstruction chosen from the record, and the warning naming --hold.

Covers randvib.identification.input_reconstruction (choose_hold, midpoint_error,
near_nyquist_fraction), SimulationSettings.for_record in
randvib.identification.settings, and the default of randvib.identification.identify
on a shaker record sampled at 1 kHz whose base acceleration has content up to
350 Hz. That record comes from a generator independent of the package: filtered
Gaussian noise, its band-limited interpolant by ``scipy.signal.resample`` and a
fourth-order Runge-Kutta integration of Eq. 1 written here, at 16 kHz.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import signal

from randvib.cli import main
from randvib.identification.identify import identify
from randvib.identification.input_reconstruction import (
    HOLD_TOLERANCE,
    choose_hold,
    midpoint_error,
    near_nyquist_fraction,
)
from randvib.identification.settings import SimulationSettings
from randvib.models.record import Record

TRUTH = {"c": 0.2, "k": 57.4, "k3": 1.2e6, "fc": 0.0058}
M = 0.0226
OFFSETS = {"input_offset": 0.3, "output_offset": 5e-4}


def rk4_displacement(fine, h, truth, every=1):
    """Eq. 1 with Coulomb friction (``truth``'s c, k, k3, fc; mass M) by RK4 at step
    ``h`` on the finely sampled base acceleration ``fine``, from rest; z (m) at every
    ``every``-th fine sample, the last entry the final state. An independent
    integrator: none of randvib's simulators."""
    c, k, k3, fc = (truth[name] for name in ("c", "k", "k3", "fc"))

    def f(z, v, y):
        return v, -(c * v + k * z + k3 * z**3 + fc * np.sign(v)) / M - y

    z = v = 0.0
    out = np.empty(len(fine) // every)
    for i in range(out.size * every - 1):
        if i % every == 0:
            out[i // every] = z
        y0, y1 = fine[i], fine[i + 1]
        ym = 0.5 * (y0 + y1)
        d1 = f(z, v, y0)
        d2 = f(z + h / 2 * d1[0], v + h / 2 * d1[1], ym)
        d3 = f(z + h / 2 * d2[0], v + h / 2 * d2[1], ym)
        d4 = f(z + h * d3[0], v + h * d3[1], y1)
        z += h / 6 * (d1[0] + 2 * d2[0] + 2 * d3[0] + d4[0])
        v += h / 6 * (d1[1] + 2 * d2[1] + 2 * d3[1] + d4[1])
    out[-1] = z
    return out


def shaker_record(duration=2.0, fs=1000.0, top=350.0, rms=25.0, up=16, seed=0):
    """Base acceleration (m/s^2) low-passed at ``top`` (8th-order Butterworth,
    forward and backward: an anti-aliased sensor) and the relative displacement
    (m) of Eq. 1 with Coulomb friction, integrated by RK4 at ``up`` x ``fs`` on
    the input's band-limited interpolant; offsets added to both channels."""
    rng = np.random.default_rng(seed)
    n, pad = int(duration * fs), 2000
    a = signal.sosfiltfilt(
        signal.butter(8, top / (fs / 2), output="sos"), rng.standard_normal(n + 2 * pad)
    )[pad:-pad]
    a = signal.sosfiltfilt(signal.butter(2, 3.0 / (fs / 2), btype="high", output="sos"), a)
    a *= rms / a.std()
    fine = signal.resample(a, n * up)  # exact at the samples, band-limited between
    out = rk4_displacement(fine, 1.0 / (fs * up), TRUTH, up)
    return Record(
        1.0 / fs,
        base_acceleration=a + OFFSETS["input_offset"],
        relative_displacement=out + OFFSETS["output_offset"],
        name="rig",
    )


@pytest.fixture(scope="module")
def rig():
    return shaker_record()


def test_default_identification_of_a_wideband_shaker_record_is_within_5_percent(rig):
    """Default options: the band-limited reconstruction is chosen (and said in the
    notes) and every parameter and offset is within 5 % of the truth (the issue's
    bar; the record is noise-free, so only the model's error remains)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)  # the right choice needs no warning
        result = identify(rig, "coulomb", m=M, progress=False)
    assert result.settings["hold"] == "bandlimited"
    assert any("band-limited" in note and "--hold" in note for note in result.notes)
    for name, true in {**TRUTH, **OFFSETS}.items():
        assert result.parameters[name] == pytest.approx(true, rel=0.05), name
    assert result.residuals.verdict in ("white", "structured")
    assert result.to_dict()["residuals"]["verdict"] == result.residuals.verdict


def test_linear_hold_on_the_wideband_record_warns_naming_hold(rig):
    """Straight lines between samples misrepresent content up to 0.35 fs: asked
    for explicitly, they are kept and the warning names --hold."""
    with pytest.warns(UserWarning, match="--hold bandlimited"):
        settings, why = SimulationSettings(hold="linear").for_record(rig)
    assert settings.hold == "linear" and "--hold" in why


def test_cli_identify_with_linear_hold_warns_on_stderr(rig, tmp_path, capsys):
    path = tmp_path / "rig.csv"
    rig.to_csv(path, float_format=None)  # every digit: the CLI reads the same record
    code = main(
        ["identify", str(path), "--model", "coulomb", "--m", str(M), "--hold", "linear"]
        + ["--generations", "1", "--popsize", "8", "--no-polish", "--no-progress"]
    )
    assert code == 0
    assert "--hold bandlimited" in capsys.readouterr().err


def test_cli_default_identify_of_a_strongly_hardening_record_is_within_5_percent(tmp_path, capsys):
    """The hardest record of the generator over seeds 0-9: at seed 1 the response
    reaches so far into the cubic range that k3 z_max^2 exceeds twice the linear
    stiffness (a k3 search box of 2 m w^2 / z_max^2 would stop the fit on its bound
    at -21 %, with c, Fc and the input offset 24 to 140 % off). ``randvib identify rig.csv --model coulomb --m 0.0226``, nothing
    else: every parameter and offset within 5 % (the record is noise-free: only
    the model's discretisation errs), nothing on a bound, no warning."""
    import json

    rig = shaker_record(seed=1)
    path = tmp_path / "rig.csv"
    rig.to_csv(path, float_format=None)  # every digit: the CLI reads the same record
    code = main(["identify", str(path), "--model", "coulomb", "--m", str(M), "--json"])
    out = capsys.readouterr()
    assert code == 0 and "--bounds" not in out.err and "--hold" not in out.err
    fit = json.loads(out.out)
    assert fit["at_bound"] == {}
    for name, true in {**TRUTH, **OFFSETS}.items():
        assert fit["parameters"][name] == pytest.approx(true, rel=0.05), name


def test_input_offset_stays_in_the_box_reported_with_it(rig):
    """A box given for the input offset bounds the search and the polish: below
    the true offset 0.3 m/s^2 the value ends on its upper edge, labelled there,
    without an interval, with a warning naming --bounds; the box reported is
    the one given."""
    box = (0.0, 0.2)
    with pytest.warns(UserWarning, match="input_offset = 0.2 m/s.* upper bound.*--bounds"):
        fit = identify(rig, "coulomb", m=M, progress=False, popsize=8, maxiter=3,
                       bounds={"input_offset": box})  # fmt: skip
    assert fit.bounds["input_offset"] == box
    assert box[0] <= fit.parameters["input_offset"] <= box[1]
    assert fit.at_bound.get("input_offset") == "upper"
    assert "input_offset" not in fit.confidence_intervals


def test_auto_keeps_linear_for_a_slow_input():
    """The paper's band (4-20 Hz) at 1 kHz: straight lines err by (pi f dt)^2 / 2
    < 2e-3 at the mid-points, below the tolerance: linear, silently."""
    rng = np.random.default_rng(1)
    x = signal.sosfiltfilt(signal.butter(4, 20 / 500, output="sos"), rng.standard_normal(4000))
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        assert choose_hold(x, 1e-3) == ("linear", "")


def test_midpoint_error_of_a_cosine_is_exact():
    """A cosine with a whole number of half periods over the record is exactly
    band-limited under the mirrored extension: the linear mid-point is
    cos(pi f) of the true value, so the relative RMS error is 1 - cos(pi f)
    (f in cycles per sample); the zero-order hold's is sqrt(2 (1 - cos(pi f)))
    at the mid-point, to the record's edge effects (one sample in n)."""
    n, half_periods = 401, 120
    f = half_periods / (2 * (n - 1))
    x = np.cos(np.pi * half_periods * np.arange(n) / (n - 1))
    assert midpoint_error(x, "linear") == pytest.approx(1 - np.cos(np.pi * f), rel=5e-3)
    assert midpoint_error(x, "zero") == pytest.approx(np.sqrt(2 * (1 - np.cos(np.pi * f))), 5e-3)
    assert midpoint_error(x, "bandlimited") == 0.0
    assert 1 - np.cos(np.pi * f) > HOLD_TOLERANCE  # so auto would choose band-limited
    assert choose_hold(x, 1.0)[0] == "bandlimited"


def test_white_input_is_not_band_limited_and_warns():
    """White noise has a tenth of its power above 0.9 x Nyquist (Welch's estimate
    of that fraction is within a few % of 0.1 on 4000 samples): auto takes the
    band-limited interpolant (lines differ from it by far more than 1 %) and
    warns, naming --hold."""
    x = np.random.default_rng(2).standard_normal(4000)
    assert near_nyquist_fraction(x) == pytest.approx(0.1, rel=0.15)
    with pytest.warns(UserWarning, match="--hold zero"):
        hold, why = choose_hold(x, 1e-3)
    assert hold == "bandlimited" and "not band-limited" in why


def test_unknown_hold_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match="`hold` must be one of auto, linear"):
        SimulationSettings(hold="sinc")
