"""Fit figures (randvib.identification.plots.figure_fit): residual panel, the shown
window stated, histogram bins from the record's length, fit and validation marked;
``identify --plot`` and ``validate --plot`` say where they wrote (randvib.cli.identify,
randvib.cli.validate).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from randvib.cli import main  # noqa: E402
from randvib.identification.plots import figure_fit, histogram_bins  # noqa: E402
from randvib.identification.prediction import predict_record  # noqa: E402
from randvib.identification.synthetic import synthetic_record  # noqa: E402
from randvib.models.presets import preset  # noqa: E402


@pytest.fixture(scope="module")
def record():
    return synthetic_record("coulomb-td1", 1.07, duration=3.0, sample_rate=500.0, seed=1)


def test_histogram_bins_follow_rice_rule():
    assert histogram_bins(500) == 16  # ceil(2 * 500^(1/3)) = ceil(15.87)
    assert histogram_bins(10) == 10 and histogram_bins(10**7) == 81


def test_figure_has_a_residual_panel_the_window_and_its_kind(record):
    import matplotlib.pyplot as plt

    pred = predict_record(preset("coulomb-td1").updated(fc=0.004), record)
    fig = figure_fit(pred, window=(0.0, 1.0), validation=True)
    ax_t, ax_r, ax_h = fig.axes[:3]
    assert ax_r.get_xlabel() == "time (s); shown: 0 to 1 s of 3 s"
    assert ax_r.get_ylabel() == "residual (mm)" and "RMS" in ax_r.get_title(loc="right")
    assert fig._suptitle.get_text().startswith("validation: ")
    assert len(ax_h.patches) == 2  # measured and simulated step histograms
    plt.close(fig)
    fig = figure_fit(pred, validation=False)
    assert fig._suptitle.get_text().startswith("fit to the training record: ")
    plt.close(fig)


def test_identify_and_validate_plot_say_where_they_wrote(record, tmp_path, capsys):
    data = tmp_path / "rig.csv"
    record.to_csv(data)
    fit = tmp_path / "fit.json"
    plot = tmp_path / "fit.png"
    args = ["identify", str(data), "--model", "coulomb", "--m", "0.0226", "--no-progress"]
    args += ["--generations", "2", "--popsize", "8", "--save", str(fit), "--plot", str(plot)]
    assert main(args) == 0
    assert f"wrote {plot}" in capsys.readouterr().out and plot.exists()
    folder = tmp_path / "figures"
    assert main(["validate", str(fit), str(data), "--plot", str(folder)]) == 0
    assert f"wrote 1 figure(s) into {folder}" in capsys.readouterr().out
    assert len(list(folder.glob("*.png"))) == 1
    # the same kind of argument as identify's: one file for one record, new unless --force
    single = tmp_path / "validation.png"
    assert main(["validate", str(fit), str(data), "--plot", str(single)]) == 0
    assert f"wrote {single}" in capsys.readouterr().out and single.exists()
    assert main(["validate", str(fit), str(data), "--plot", str(single)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["validate", str(fit), str(data), str(data), "--plot", str(single)]) == 2
    assert "one file, for one record" in capsys.readouterr().err
