"""``randvib simulate`` under filtered excitation: the CLI runs what the Python API runs.

White noise gives what the API gives; band-pass and Kanai-Tajimi input
give the same numbers as :func:`randvib.simulate` with the same excitation
object (band-limited and tabulated input synthesised, a record simulated on
itself); what Monte Carlo cannot take is refused with one line (exit 2).

Covers :mod:`randvib.cli.simulate` with the excitation options of
:mod:`randvib.cli._excitation`, and the record simulated on itself
(:mod:`randvib.montecarlo.on_record`).
"""

import json

import numpy as np
import pandas as pd
import pytest
from _cli import one_line_error

import randvib as rv
from randvib.cli import main

COMMON = ["--preset", "figure9", "--paths", "32", "--t-end", "1.0", "--burn-in", "0.5"]
KW = dict(t_end=1.0, burn_in=0.5, n_paths=32, dt=1e-4, scheme="heun", seed=0)


def _json(capsys, *argv):
    code = main(["simulate", *COMMON, *argv, "--json"])
    out = capsys.readouterr().out
    assert code == 0, out
    summary = json.loads(out)
    summary.pop("wall_time")
    # the CLI's units entry (randvib.cli._output.with_units) is not part of the summary
    assert summary.pop("units")["power_electrical"] == "W"
    return summary


def _api(psd):
    summary = rv.simulate(rv.preset("figure9"), psd, progress=False, **KW).summary()
    summary.pop("wall_time")
    return json.loads(json.dumps(summary))


def test_white_noise_output_is_unchanged(capsys):
    assert _json(capsys, "--psd", "1") == _api(1.0)


@pytest.mark.parametrize(
    ("argv", "excitation"),
    [
        (["--excitation", "band-pass", "--f0", "8", "--zeta", "0.3"], rv.BandPass(1.0, 8.0, 0.3)),
        (
            ["--excitation", "kanai-tajimi", "--f0", "8", "--zeta", "0.5"],
            rv.KanaiTajimi(1.0, 8.0, 0.5),
        ),
    ],
)
def test_filtered_excitation_equals_the_python_api(capsys, argv, excitation):
    cli = _json(capsys, "--psd", "1", *argv)
    assert cli == _api(excitation)
    assert cli["excitation"]  # the spectrum used is recorded


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (
            ["--excitation", "band-limited", "--f-lo", "4", "--f-hi", "20", "--control-variates"],
            "`--control-variates` needs white noise or a filtered spectrum",
        ),
        (["--excitation", "band-pass", "--f0", "-8", "--zeta", "0.3"], "`--f0`"),
        (["--f0", "8"], "`--f0` needs `--excitation"),
    ],
)
def test_what_monte_carlo_cannot_take_is_one_line_exit_2(capsys, argv, fragment):
    one_line_error(capsys, ["simulate", *COMMON, "--psd", "1", *argv], fragment)


def test_band_limited_and_table_equal_the_python_api(capsys, tmp_path):
    argv = ["--excitation", "band-limited", "--f-lo", "4", "--f-hi", "20"]
    assert _json(capsys, "--psd", "0.5", *argv) == _api(rv.BandLimited(0.5, 4.0, 20.0))
    table = tmp_path / "psd.csv"
    table.write_text("frequency,psd\n0,0\n5,1\n15,1\n30,0\n")
    assert _json(capsys, "--psd-file", str(table)) == _api(rv.Tabulated.from_csv(table))


def _record(tmp_path, n=8000, dt=1e-3, bad=None):
    x = rv.BandLimited(1.0, 4.0, 20.0).sample(n * dt, dt, 1, seed=1)[0]
    t = np.arange(n) * dt
    if bad == "nan":
        x[10] = np.nan
    if bad == "uneven":
        t[10] += 0.3 * dt
    path = tmp_path / "record.csv"
    pd.DataFrame({"time": t, "base_acceleration": x}).to_csv(path, index=False)
    return path


def test_record_equals_monte_carlo_on_record(capsys, tmp_path):
    path = _record(tmp_path)
    code = main(["simulate", "--preset", "figure9", "--record", str(path), "--segments", "4",
                 "--burn-in", "0.5", "--dt", "5e-4", "--json"])  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    api = rv.monte_carlo_on_record(
        rv.preset("figure9"), rv.Measured.from_csv(path), segments=4, burn_in=0.5, substeps=2
    ).summary()
    out.pop("wall_time"), api.pop("wall_time"), out.pop("units")
    assert out == json.loads(json.dumps(api))
    assert out["n_paths"] == 4 and out["psd"] is None


@pytest.mark.parametrize(
    ("argv", "bad", "fragment"),
    [
        (["--paths", "10"], None, "`--paths` does not apply to `--record`"),
        (["--t-end", "3"], None, "`--t-end` does not apply"),
        (["--dt", "3e-4"], None, "`--dt` must divide the record's step"),
        (["--segments", "1"], None, "argument --segments: must be"),
        (["--burn-in", "100"], None, "hold no window"),
        ([], "nan", "`--record`"),
        ([], "uneven", "evenly spaced"),
    ],
)
def test_bad_record_options_one_line_exit_2(capsys, tmp_path, argv, bad, fragment):
    path = _record(tmp_path, bad=bad)
    one_line_error(
        capsys, ["simulate", "--preset", "figure9", "--record", str(path), *argv], fragment
    )


def test_segments_without_record_one_line(capsys):
    one_line_error(
        capsys, ["simulate", *COMMON, "--psd", "1", "--segments", "3"], "needs `--record`"
    )


def test_band_pass_control_variates_equal_the_python_api(capsys):
    argv = ["--excitation", "band-pass", "--f0", "8", "--zeta", "0.3", "--control-variates"]
    cli = _json(capsys, "--psd", "1", *argv)
    api = rv.simulate(
        rv.preset("figure9"), rv.BandPass(1.0, 8.0, 0.3), progress=False, control_variates=True,
        **KW,
    ).summary()  # fmt: skip
    api.pop("wall_time")
    assert cli == json.loads(json.dumps(api)) and cli["control_variates"] is True
