"""Command-line paths that had no test: table output, --control-variates, --plot, every
study from the command line (sizes shrunk by monkeypatching the study's grid), and the
error branches. Every user error must end with exit status 2 and one line naming the
argument.

Covers the commands' modules :mod:`randvib.cli.simulate`, :mod:`randvib.cli.identify`,
:mod:`randvib.cli.validate` and :mod:`randvib.cli.study`, with the identification
figures of ``--plot`` (:mod:`randvib.identification.plots`).
"""

import json

import _identification as H
import matplotlib.image
import numpy as np
import pytest
from _cli import one_line_error, run
from study_checks import check_study_run

import randvib as rv
from randvib.identification.prediction import validate as validate_api
from randvib.models.record import read_record
from randvib.montecarlo.simulation import simulate
from randvib.montecarlo.sweep import SweepSettings

FIG9 = rv.preset("figure9")
SIM = ["--paths", "16", "--t-end", "0.4", "--burn-in", "0.1", "--seed", "3"]


def table_rows(out):
    """{first cell: other cells} of a tabulate 'simple' table; a half-width's cell
    "± 0.00094" is one cell, its number."""
    rows = {}
    for line in out.splitlines():
        cells = [c for c in line.split() if c != "±"]
        if len(cells) >= 2 and not set(line) <= set("- "):
            rows[cells[0]] = cells[1:]
    return rows


def png_ok(path):
    assert path.is_file() and path.stat().st_size > 0
    image = matplotlib.image.imread(path)
    assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100


# ----------------------------------------------------------------- simulate
def test_simulate_table_shows_monte_carlo_and_eq32(capsys):
    code, out, _ = run(capsys, "simulate", "--preset", "figure9", "--psd", "1", *SIM)
    assert code == 0
    rows = table_rows(out)
    direct = simulate(FIG9, 1.0, t_end=0.4, dt=1e-4, n_paths=16, burn_in=0.1, seed=3)
    mc, ci, lin, unit = rows["power_electrical"]
    # shown to the precision the interval supports: the half-width to two
    # significant digits, the mean to the same decimal place
    assert float(ci) == pytest.approx(direct.power_electrical.ci95, rel=0.05)
    assert float(mc) == pytest.approx(direct.power_electrical.mean, abs=0.05 * float(ci))
    assert len(ci.replace("0.", "").lstrip("0")) == 2 and len(mc.split(".")[1]) == len(
        ci.split(".")[1]
    )
    assert float(lin) == pytest.approx(rv.expected_power(FIG9, 1.0), rel=1e-5) and unit == "W"
    assert float(rows["velocity_variance"][2]) == pytest.approx(
        1.0 * FIG9.m / (4 * rv.equivalent_damping(FIG9, 1.0)), rel=1e-5
    )
    assert "16 paths x 0.3 s averaged" in out and "seed 3" in out


def test_simulate_control_variates_reach_the_simulation(capsys):
    code, out, _ = run(
        capsys,
        "simulate",
        "--preset",
        "figure9",
        "--psd",
        "1",
        *SIM,
        "--control-variates",
        "--json",
    )
    assert code == 0
    data = json.loads(out)
    kw = dict(t_end=0.4, dt=1e-4, n_paths=16, burn_in=0.1, seed=3)
    cv = simulate(FIG9, 1.0, companion=True, control_variates=True, **kw).summary()
    plain = simulate(FIG9, 1.0, **kw).summary()
    for key in ("power_electrical", "velocity_variance"):
        assert data[key] == pytest.approx(cv[key], rel=1e-12)
        assert data[key]["mean"] != plain[key]["mean"]


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["--paths", "0"], "argument --paths"),
        (["--dt", "0"], "`--dt`"),
        (["--t-end", "1", "--burn-in", "1"], "`--burn-in`"),
        (["--threads", "0"], "argument --threads"),
    ],
)
def test_simulate_bad_options(capsys, argv, fragment):
    one_line_error(capsys, ["simulate", "--preset", "figure9", "--psd", "1", *argv], fragment)


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (
            ["--preset", "figure9", "--friction", "coulomb", "--beta", "5"],
            "`--beta` applies to tanh",
        ),
        (["--preset", "figure9", "--beta", "5"], "`--beta` applies to tanh"),
        (
            ["--m", "1", "--c-m", "1", "--c-e", "1", "--k", "1", "--fc", "1"],
            "`--fc` needs `--friction",
        ),
        (["--preset", "figure9", "--friction", "tanh"], "`--beta` is required for tanh friction"),
        (["--m", "1", "--c-m", "1", "--c-e", "1"], "`--k` is required"),
        (
            ["--preset", "figure9", "--c-e", "0.1", "--alpha", "0.2"],
            "give either `--c-e` or `--alpha",
        ),
        (["--m", "1", "--c-m", "1", "--k", "1", "--alpha", "0.2"], "must be given together"),
    ],
)
def test_device_option_errors(capsys, argv, fragment):
    one_line_error(capsys, ["simulate", "--psd", "1", *argv], fragment)


def test_simulate_api_rejects_non_finite_dw_and_bad_histogram_range():
    kw = dict(t_end=0.01, dt=1e-4, n_paths=2)
    dw = np.zeros((2, 100))
    dw[1, 7] = np.nan
    with pytest.raises(ValueError, match="`dW` must be finite"):
        simulate(FIG9, 1.0, dW=dw, **kw)
    dw[1, 7] = np.inf
    with pytest.raises(ValueError, match="`dW` must be finite"):
        simulate(FIG9, 1.0, dW=dw, **kw)
    for bad in (((0.0, 1.0),), ((0.0, 1.0), (1.0, -1.0)), ((1.0, 1.0), (-1.0, 1.0))):
        with pytest.raises(ValueError, match="`histogram_range` must be"):
            simulate(FIG9, 1.0, histogram_bins=8, histogram_range=bad, **kw)


# ----------------------------------------------------------------- identify / validate
@pytest.fixture(scope="module")
def records(tmp_path_factory):
    from randvib.studies import load

    make_test = load("identification").make_test

    folder = tmp_path_factory.mktemp("rec")
    paths = []
    for n in (3, 6):
        rec, _ = make_test(n, duration=1.0, fs=400.0, seed=0)
        path = folder / f"test{n}.csv"
        rec.to_csv(path)
        paths.append(path)
    return paths


IDENT = ["--model", "coulomb", "--m", "0.0226", "--popsize", "8", "--generations", "2"]


def test_identify_table_and_plot(tmp_path, capsys, records):
    params, plot = tmp_path / "p.json", tmp_path / "fit.png"
    argv = ["identify", records[0], *IDENT, "--no-polish", "--no-progress"]
    code, out, _ = run(capsys, *argv, "--save", params, "--plot", plot)
    assert code == 0
    saved = json.loads(params.read_text())
    rows = table_rows(out)
    for name, value in saved["parameters"].items():
        assert float(rows[name][0]) == pytest.approx(value, rel=1e-5)
        assert rows[name][-1] == ("fixed" if name == "m" else "identified")
    assert f"J = {saved['cost']:.6g} (Eq. 11)" in out
    png_ok(plot)
    # a path the user named is written as asked: no checksum file left beside it
    assert not (tmp_path / ".randvib-written.json").exists()
    # an existing --save or --plot file is refused before any work
    one_line_error(capsys, [*argv, "--save", params], "`--save`")
    one_line_error(capsys, [*argv, "--plot", plot], "`--plot`")
    assert run(capsys, *argv, "--plot", plot, "--force")[0] == 0


def test_validate_table_and_plots(tmp_path, capsys, records):
    params = tmp_path / "p.json"
    parameters = {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 70742.0, "fc": 0.0058}
    params.write_text(json.dumps({"model": "coulomb", "parameters": parameters}))
    plots = tmp_path / "plots"
    code, out, _ = run(capsys, "validate", params, *records, "--plot", plots)
    assert code == 0
    device = H.harvester(parameters)
    expected = validate_api(device, [read_record(p) for p in records], substeps=4)
    rows = table_rows(out)
    for row in expected:
        samples, cost, rms, offsets = rows[row.record][:4]  # then the residual's verdict
        assert offsets == row.offsets_source
        assert float(cost) == pytest.approx(row.cost, rel=1e-5)
        assert float(rms) == pytest.approx(row.rms_error, rel=1e-5)
        assert int(samples) == row.samples
    pngs = sorted(plots.glob("*.png"))
    assert [p.name for p in pngs] == ["00_test3.png", "01_test6.png"]
    for p in pngs:
        png_ok(p)
    # the folder now holds plots: a second run into it is refused
    one_line_error(capsys, ["validate", params, records[0], "--plot", plots], "`--plot` folder")


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        (None, "parameter file"),
        ("not json", "is not an identification result"),
        ('{"model": "dry", "parameters": {}}', "model 'dry' is not one of"),
    ],
)
def test_validate_bad_parameter_file(tmp_path, capsys, records, content, fragment):
    params = tmp_path / "p.json"
    if content is not None:
        params.write_text(content)
    one_line_error(capsys, ["validate", params, records[0]], fragment)


def test_validate_bad_set(tmp_path, capsys, records):
    params = tmp_path / "p.json"
    params.write_text('{"model": "viscous", "parameters": {"m": 1, "c": 1, "k": 1, "k3": 0}}')
    one_line_error(capsys, ["validate", params, records[0], "--set", "k=abc"], "`--set k`")


# ----------------------------------------------------------------- studies from the CLI
TINY = SweepSettings(dt=1e-4, window=0.2, burn_in=0.1, min_paths=48, max_paths=48, batch_paths=48)


def _study(capsys, name, out):
    code, stdout, err = run(
        capsys, "study", name, "--quick", "--out", out, "--workers", "1", "--no-progress"
    )
    assert code == 0, err
    check_study_run(stdout, out)
    return (out / "report.md").read_text()


# `study interaction` and `study linearisation-accuracy` from the CLI: the end-to-end
# tests in tests/test_studies.py run them through main() with a monkeypatched grid.


def test_study_identification_cli(tmp_path, capsys, monkeypatch):
    from randvib.studies import load

    identification = load("identification")
    monkeypatch.setattr(
        identification,
        "settings_for",
        lambda quick: dict(duration=0.6, fs=250.0, popsize=6, generations=1, substeps=2),
    )
    out = tmp_path / "ident"
    report = _study(capsys, "identification", out)
    import pandas as pd

    fig8 = pd.read_csv(out / "figure8.csv")
    assert len(fig8) == 4
    verdict = json.loads((out / "verdicts.json").read_text())
    assert verdict["figure8"]["sentence"] in report
    assert len(list((out / "records").glob("test*.csv"))) == 9


def test_study_linearisation_vs_averaging_cli(tmp_path, capsys, monkeypatch):
    """A tiny run from the command line, and its rerun: every case resumed from the store
    (its files untouched), the same table. (The quick run's accuracy criteria:
    tests/test_averaging.py.)"""
    import pandas as pd

    from randvib.studies import load, methods

    lva = load("linearisation-vs-averaging")

    mc = {"n_paths": 16, "window": 0.5, "burn_in": 0.2, "dt": 5e-4}
    axes = {"psds": (1.0,), "kappas": (0.0, 0.5), "k3s": (0.0, 7e6), "mc": mc}
    monkeypatch.setattr(lva, "grid", lambda quick: axes)
    monkeypatch.setattr(methods, "FPK_REFERENCE_CELLS", 64)  # the reference is not checked here
    out = tmp_path / "lva"
    report = _study(capsys, "linearisation-vs-averaging", out)
    verdict = json.loads((out / "verdicts.json").read_text())
    assert verdict["points"] == 4 and verdict["reading"] in report
    results = pd.read_csv(out / "results.csv")
    stored = sorted((out / "ensembles" / "points").glob("*.npy"))
    assert len(stored) == len(results) == 4
    stamps = [p.stat().st_mtime_ns for p in stored]
    _study(capsys, "linearisation-vs-averaging", out)
    assert [p.stat().st_mtime_ns for p in stored] == stamps
    pd.testing.assert_frame_equal(pd.read_csv(out / "results.csv"), results)
    # its Monte Carlo runs on --workers processes (rv.run_ensembles), not in-process threads
    one_line_error(
        capsys,
        ["study", "linearisation-vs-averaging", "--out", tmp_path / "x", "--threads", "2"],
        "has no `--threads` option",
    )


def test_study_out_is_a_file(tmp_path, capsys):
    target = tmp_path / "file"
    target.write_text("x")
    one_line_error(capsys, ["study", "figure9", "--out", target], "exists and is not a folder")
