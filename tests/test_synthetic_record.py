"""Synthetic records (randvib.identification.synthetic, CLI ``randvib record``)."""

import _identification as H
import numpy as np
import pytest

from randvib import BandLimited, Harvester, preset, read_record, synthetic_record
from randvib.cli import main
from randvib.identification.identify import identify
from randvib.identification.record_response import record_response
from randvib.models.excitation import band_limited_excitation
from randvib.models.friction import Coulomb

#: Paper Table 2, Coulomb model, training data 1 (as tests/_identification.py).
TRUTH = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058)
DEVICE = Harvester(
    m=TRUTH["m"],
    c_m=TRUTH["c"],
    c_e=0.0,
    k=TRUTH["k"],
    k3=TRUTH["k3"],
    friction=Coulomb(TRUTH["fc"]),
)
#: Precision of tests/test_identification.py (TOL there).
TOL = 1e-4
SHORT = dict(duration=2.0, sample_rate=500.0, seed=3)


@pytest.fixture(scope="module")
def clean():
    return synthetic_record(DEVICE, 1.07, **SHORT)


def test_csv_round_trips_exactly(clean, tmp_path):
    path = tmp_path / "r.csv"
    clean.to_csv(path, float_format=None)
    back = read_record(path)
    np.testing.assert_array_equal(back.z, clean.z)
    np.testing.assert_array_equal(back.input, clean.input)
    assert back.input_kind == clean.input_kind
    # dt is the written time column's step, (t_last - t_0) / (n - 1): equal to rounding.
    assert back.dt == pytest.approx(clean.dt, rel=1e-12)
    with pytest.raises(FileExistsError, match="overwrite=True"):
        clean.to_csv(path)
    clean.to_csv(path, overwrite=True)


@pytest.mark.parametrize("kind", ["base_acceleration", "base_displacement"])
def test_noise_free_record_is_the_record_response(kind):
    rec = synthetic_record(DEVICE, 1.07, input=kind, substeps=6, **SHORT)
    ex = band_limited_excitation(2.0, 500.0, 1.07, seed=np.random.default_rng(3).spawn(2)[0])
    np.testing.assert_array_equal(rec.input, ex[kind])
    sim = record_response(DEVICE, ex, input_kind=kind, substeps=6)
    np.testing.assert_array_equal(rec.z, sim.z[0])


def test_offsets_appear_exactly_and_noise_has_its_rms(clean):
    shifted = synthetic_record(DEVICE, 1.07, offset_z=2e-4, offset_input=-0.3, **SHORT)
    assert np.mean(shifted.z - clean.z) == pytest.approx(2e-4, rel=1e-9)
    assert np.mean(shifted.input - clean.input) == pytest.approx(-0.3, rel=1e-12)
    sigma = 1e-5
    noisy = synthetic_record(DEVICE, 1.07, noise_z=sigma, noise_input=0.01, **SHORT)
    np.testing.assert_array_equal(noisy.input - clean.input != 0, True)
    eps = noisy.z - clean.z
    n = eps.size
    # n s^2 / sigma^2 ~ chi^2(n): its 5-sigma band is sigma^2 (1 +- 5 sqrt(2/n)).
    assert abs(np.mean(eps**2) / sigma**2 - 1) < 5 * np.sqrt(2 / n)
    assert abs(np.mean(eps)) < 5 * sigma / np.sqrt(n)
    # The noise draws do not change the excitation.
    np.testing.assert_array_equal(
        synthetic_record(DEVICE, 1.07, noise_z=sigma, **SHORT).input, clean.input
    )


def test_band_limited_spectrum_and_presets():
    rec = synthetic_record(
        "coulomb-td1", BandLimited(0.07, 4.0, 20.0), input="base_displacement", **SHORT
    )
    assert rec.input_kind == "base_displacement" and rec.n == 1000
    same = synthetic_record(
        preset("coulomb-td1"), BandLimited(0.07, 4.0, 20.0), input="base_displacement", **SHORT
    )
    np.testing.assert_array_equal(rec.z, same.z)


def test_identify_recovers_the_truth_from_a_clean_record(clean):
    """To TOL of the truth with the default measurement model.

    The initial state and both offsets are estimated, so nothing but the
    integration step (4 sub-steps against the record's 8) separates the
    optimum from the truth; the start from the record's samples (the
    linearised ``bias`` of tests/test_identification.py) is gone. The
    offsets come out at zero to within their standard errors' scale.
    """
    res = identify(clean, "coulomb", m=TRUTH["m"], popsize=30, maxiter=80, seed=1)
    err = np.array([np.log(res.parameters[n] / TRUTH[n]) for n in H.FREE])
    assert np.all(np.abs(err) <= TOL), dict(zip(H.FREE, err, strict=True))
    assert abs(res.parameters["output_offset"]) < TOL * np.std(clean.z)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (dict(duration=-1.0), "`duration` must be > 0"),
        (dict(sample_rate=0.0), "`sample_rate` must be > 0"),
        (dict(input="force"), "`input` must be one of base_acceleration, base_displacement"),
        (dict(noise_z=-1e-6), "`noise_z` must be >= 0"),
        (dict(offset_input=np.nan), "`offset_input`"),
        (dict(substeps=0), "`substeps`"),
        (dict(excitation="loud"), "`excitation` must be an RMS"),
        (dict(excitation=-1.0), "`excitation \\(RMS base acceleration\\)` must be > 0"),
        (dict(device="nope"), "`device` must be a Harvester or one of"),
        (
            dict(excitation=BandLimited(1.0, 0.0, 20.0), input="base_displacement"),
            "needs an excitation without power at 0 Hz",
        ),
    ],
)
def test_errors_name_the_argument(kwargs, message):
    args = dict(device=DEVICE, excitation=1.07, **SHORT)
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        synthetic_record(args.pop("device"), args.pop("excitation"), **args)


def test_cli_writes_a_record_identify_reads_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "rec.csv"
    argv = ["record", "--preset", "coulomb-td1", "--rms", "1.07", "--duration", "1",
            "--sample-rate", "500", "--offset-z", "1e-4", "--seed", "3", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    rec = read_record(out)
    expected = synthetic_record(
        "coulomb-td1", 1.07, duration=1.0, sample_rate=500.0, seed=3, offset_z=1e-4
    )
    np.testing.assert_array_equal(rec.z, expected.z)
    capsys.readouterr()
    assert main(argv) == 2
    assert "exists" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ([], "give exactly one of `--rms`"),
        (["--rms", "1", "--psd", "0.1"], "give exactly one of `--rms`"),
        (["--rms", "1", "--input", "force"], "`--input` must be one of"),
        (["--rms", "1", "--f-lo", "30"], "`--f-hi` must be > `--f-lo`"),
        (["--rms", "1", "--noise-z", "-1"], "`--noise-z` must be >= 0"),
    ],
)
def test_cli_errors_are_one_line(tmp_path, capsys, extra, message):
    out = tmp_path / "rec.csv"
    assert main(["record", "--preset", "coulomb-td1", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not out.exists()
