"""Answers that were silently wrong: each case refused or flagged rather than returned.

Covers the refusal of a non-confining potential in
:mod:`randvib.identification.synthetic` (and ``randvib record``, :mod:`randvib.cli.record`).
"""

import pytest
from _cli import one_line_error

import randvib as rv


def test_synthetic_record_refuses_a_non_confining_potential():
    """k = -28.7 N/m, k3 = 0: the mass escapes (|z| ~ 1e269 m); no record to write."""
    device = rv.Harvester(m=0.0226, c_m=0.05, c_e=0.05, k=-28.7, k3=0.0)
    with pytest.raises(ValueError, match="not confining"):
        rv.synthetic_record(device, 1.0, duration=1.0, sample_rate=200.0, seed=0)


def test_record_command_refuses_a_non_confining_potential(capsys, tmp_path):
    out = tmp_path / "r.csv"
    argv = ["record", "--preset", "viscous-td1", "--k=-28.7", "--k3", "0", "--rms", "1",
            "--out", out]  # fmt: skip
    one_line_error(capsys, argv, "not confining")
    assert not out.exists()
