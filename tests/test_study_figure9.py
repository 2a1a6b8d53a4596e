"""End to end: ``randvib study figure9 --quick`` writes its figures, tables and verdicts."""

import pandas as pd

from randvib.cli import main


def test_figure9_quick_end_to_end(tmp_path, capsys):
    out = tmp_path / "f9"
    argv = ["study", "figure9", "--quick", "--out", str(out), "--workers", "1", "--no-progress"]
    assert main(argv) == 0
    for name in (
        "figure9.png",
        "interaction.png",
        "results.csv",
        "interaction.csv",
        "step_check.csv",
        "curves.csv",
        "report.md",
        "metadata.json",
    ):
        assert (out / name).exists(), name
    table = pd.read_csv(out / "results.csv")
    assert len(table) == 3 * 2 * 7
    rel = table.power_electrical_ci95 / table.power_electrical
    assert ((rel <= 0.01) | (table.n_paths >= 4096)).all()
    # every friction-free point: Monte Carlo with control variates equals Eq. 20 exactly
    free = table[table.fc == 0]
    assert (abs(free.linearisation_power / free.power_electrical - 1) < 1e-9).all()
    report = (out / "report.md").read_text()
    assert "Verdict on the paper's first claim" in report
    assert "Verdict on the paper's second claim" in report
    assert "Time-step bias below statistical error" in report
    # a second run into the same folder resumes (nothing recomputed, same numbers)
    assert main(argv) == 0
    assert pd.read_csv(out / "results.csv").equals(table)
    # a different configuration into that folder is refused with one line, exit 2
    capsys.readouterr()
    assert main(["study", "figure9", "--out", str(out), "--workers", "1", "--no-progress"]) == 2
    assert "different run" in capsys.readouterr().err


def test_unknown_study(capsys, tmp_path):
    assert main(["study", "nope", "--out", str(tmp_path / "x")]) == 2
    assert "unknown study 'nope'" in capsys.readouterr().err
