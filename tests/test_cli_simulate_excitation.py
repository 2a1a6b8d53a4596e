"""``randvib simulate`` under filtered excitation: the CLI runs what the Python API runs.

White noise must stay exactly as before; band-pass and Kanai-Tajimi input
give the same numbers as :func:`randvib.simulate` with the same excitation
object; what Monte Carlo cannot take yet is refused with one line (exit 2).
"""

import json

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
            ["--excitation", "band-limited", "--f-lo", "4", "--f-hi", "20"],
            "statistical_linearisation",
        ),
        (
            ["--excitation", "band-pass", "--f0", "8", "--zeta", "0.3", "--control-variates"],
            "control",
        ),
        (["--excitation", "band-pass", "--f0", "-8", "--zeta", "0.3"], "`--f0`"),
        (["--f0", "8"], "`--f0` needs `--excitation"),
    ],
)
def test_what_monte_carlo_cannot_take_is_one_line_exit_2(capsys, argv, fragment):
    one_line_error(capsys, ["simulate", *COMMON, "--psd", "1", *argv], fragment)
