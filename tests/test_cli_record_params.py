"""``randvib record`` without --c-e and the parameters it saves; the units of a fit's offsets.

Covers randvib.cli.record (the parameters' JSON beside the CSV), the device
options of randvib.cli._device (--c-e defaults to 0, no electrical damping) and
IdentificationResult.unit in randvib.identification.result (input_offset in the
input channel's unit in to_dict, to_frame and the CLI table alike).
"""

from __future__ import annotations

import json

import pytest

from randvib.cli import main
from randvib.identification.identify import identify
from randvib.identification.synthetic import synthetic_record

DEVICE = [
    "--m",
    "0.0226",
    "--c-m",
    "0.05",
    "--k",
    "57.4",
    "--k3",
    "7e4",
    "--friction",
    "coulomb",
    "--fc",
    "0.0058",
]


def test_record_needs_no_c_e_and_saves_what_it_simulated(tmp_path, capsys):
    out = tmp_path / "rig.csv"
    args = ["record", *DEVICE, "--rms", "1.07", "--duration", "1", "--seed", "3"]
    assert main([*args, "--offset-input", "0.2", "--out", str(out)]) == 0
    saved = json.loads(out.with_suffix(".json").read_text())
    assert saved["device"]["c_e"] == 0.0 and saved["device"]["k3"] == 7e4
    assert saved["device"]["friction"] == "coulomb" and saved["device"]["fc"] == 0.0058
    assert saved["seed"] == 3 and saved["sensors"]["offset_input"] == 0.2
    assert saved["excitation"]["rms"] == 1.07
    assert str(out.with_suffix(".json")) in capsys.readouterr().out
    # a second run keeps both files unless --force
    assert main([*args, "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert json.loads(out.with_suffix(".json").read_text()) == saved


def test_record_refuses_an_existing_parameters_file(tmp_path, capsys):
    out = tmp_path / "rig.csv"
    out.with_suffix(".json").write_text("{}")
    code = main(["record", *DEVICE, "--rms", "1.07", "--duration", "1", "--out", str(out)])
    assert code == 2 and "exists" in capsys.readouterr().err
    assert out.with_suffix(".json").read_text() == "{}" and not out.exists()


def test_power_needs_no_c_e(capsys):
    assert main(["power", *DEVICE[:6], "--k3", "0", "--psd", "0.01", "--json"]) == 0


@pytest.fixture(scope="module")
def fit():
    rec = synthetic_record("coulomb-td1", 1.07, duration=1.0, sample_rate=500.0, seed=1)
    return identify(rec, "coulomb", m=0.0226, maxiter=2, popsize=8)


def test_input_offset_has_the_input_channels_unit_everywhere(fit):
    assert fit.input_kind == "base_acceleration"
    assert fit.unit("input_offset") == "m/s^2"
    assert fit.to_dict()["units"]["input_offset"] == "m/s^2"
    frame = fit.to_frame()
    assert frame.loc["input_offset", "unit"] == "m/s^2"
    assert frame.loc["output_offset", "unit"] == "m"
    assert list(frame.index) == list(fit.parameters)


def test_identify_shows_progress_by_default_in_python():
    import inspect

    assert inspect.signature(identify).parameters["progress"].default is True
