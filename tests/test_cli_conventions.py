"""One set of conventions for every command, and output for people (the command line).

The parser walk below runs over every registered subcommand, so that a new
command keeps the conventions: defaults shown in ``--help``, the shared flags
present with one meaning, choices declared as choices.

Covers :mod:`randvib.cli` (the parser, shared flags, one-line errors, the options named
differently from the API), the tables and device lines of :mod:`randvib.cli._output` and
:mod:`randvib.cli._device`, and the digits they print (:mod:`randvib.formatting`); help
without importing the commands and a command's help kept (:mod:`randvib.cli._help`), and
``randvib compile`` (:mod:`randvib.cli.compile`).
"""

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import randvib as rv
from randvib.cli import (
    API_NAMES,
    COMPILING,
    HelpFormatter,
    build_parser,
    cli_wording,
    compile_notice,
    one_line_choice_error,
)
from randvib.cli.power import sweep_values
from randvib.formatting import estimate_parts as format_estimate
from randvib.formatting import with_standard_error
from randvib.models.excitation import BandLimited
from randvib.montecarlo.ensembles import GROUP_SEEDS
from tests._cli import fit_args, one_line_error, run

ROOT = Path(__file__).resolve().parents[1]
FIG9 = rv.preset("figure9")
WIRED = rv.Harvester.from_electrical(
    m=0.0226, c_m=0.049, k=57.4, alpha=0.1992, r_load=2.0, r_coil=0.48, friction=rv.Coulomb(0.0058)
)
WIRED_ARGS = ["--m", "0.0226", "--c-m", "0.049", "--k", "57.4", "--alpha", "0.1992"]
WIRED_ARGS += ["--r-load", "2", "--r-coil", "0.48", "--friction", "coulomb", "--fc", "0.0058"]


def subcommands() -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def options(parser) -> dict[str, argparse.Action]:
    return {flag: a for a in parser._actions for flag in a.option_strings}


# ------------------------------------------------------------- the parser walk
@pytest.mark.parametrize("name", list(subcommands()))
def test_every_default_is_shown_in_help(name):
    parser = subcommands()[name]
    formatter = HelpFormatter(prog=parser.prog)
    for action in parser._actions:
        nothing = action.default is None or action.default is False
        if not action.option_strings or nothing or action.default == argparse.SUPPRESS:
            continue
        text = formatter._expand_help(action)
        assert "default" in text, (name, action.option_strings, text)
    # options whose default is decided later say it in their own text
    if name == "simulate":
        flags = options(parser)
        for flag in ("--t-end", "--burn-in", "--paths", "--dt", "--method", "--seed"):
            assert "default" in formatter._expand_help(flags[flag]), flag


#: Shared flags: the commands that must have them, and what each must be.
SHARED = {
    "--json": ({"power", "simulate", "identify", "validate"}, dict(const=True, default=False)),
    "--seed": ({"simulate", "record", "identify", "study"}, dict(default=0)),
    "--no-progress": ({"simulate", "identify", "study"}, dict(const=True, default=False)),
}


@pytest.mark.parametrize("flag", list(SHARED))
def test_shared_flags_have_one_meaning(flag):
    commands, spec = SHARED[flag]
    for name, parser in subcommands().items():
        action = options(parser).get(flag)
        if name in commands:
            assert action is not None, (name, flag)
        if action is not None:
            for attribute, value in spec.items():
                assert getattr(action, attribute) == value, (name, flag, attribute)
            if flag == "--seed":  # one integer type: 0 .. 2^64 - 1, float notation of an integer
                # design's Monte Carlo runs on the paired-ensemble seed GROUP_SEEDS * seed
                largest = (2**64 - 1) // (GROUP_SEEDS if name == "design" else 1)
                assert action.type("12") == 12 and action.type("1e3") == 1000, name
                assert action.type(str(largest)) == largest, name
                for bad in ("-1", str(largest + 1), "0.5"):
                    with pytest.raises(argparse.ArgumentTypeError):
                        action.type(bad)


def test_every_output_file_option_has_force():
    """A command that writes a named file or folder overwrites it only with --force."""
    writers = ("--out", "--save", "--csv", "--plot")
    for name, parser in subcommands().items():
        flags = options(parser)
        if any(w in flags for w in writers):
            assert "--force" in flags, name


#: Option destinations that name one of a fixed set: declared as argparse choices.
CHOICE_DESTS = ("method", "friction", "coupling", "preset", "excitation", "input", "model")
CHOICE_DESTS += ("hold", "input_kind")
CHOICE_DESTS += ("name",)  # randvib study NAME


def test_choices_are_declared():
    seen = set()
    for name, parser in subcommands().items():
        for action in parser._actions:
            if action.dest in CHOICE_DESTS:
                assert action.choices is not None, (name, action.dest)
                seen.add(action.dest)
    assert seen == set(CHOICE_DESTS)


def test_docs_document_every_renamed_option():
    readme = (ROOT / "docs" / "command_line.md").read_text()
    for option, api in API_NAMES.items():
        assert f"| `{option}` | {api} |" in readme, option


# ------------------------------------------------------------- errors and pipes
@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["power", "--preset", "figure9", "--psd", "1", "--method", "exact"], "`--method` must be"),
        (["simulate", "--preset", "figure9", "--psd", "1", "--method", "rk4"], "got 'rk4'"),
        (["power", "--preset", "figure9", "--psd", "1", "--coupling", "x"], "`--coupling` must"),
        (["record", "--preset", "figure9", "--rms", "1", "--out", "x.csv", "--input", "f"], "KIND"),
    ],
)
def test_choice_errors_are_one_line(capsys, argv, fragment):
    one_line_error(capsys, argv, fragment if fragment != "KIND" else "`--input` must be one of")


def test_argparse_choice_message_in_project_words():
    text = "argument --x: invalid choice: 'c' (choose from 'a', 'b')"
    assert one_line_choice_error(text) == "`--x` must be one of a, b; got 'c'"
    assert one_line_choice_error("unrecognized arguments: --y") == "unrecognized arguments: --y"


def test_closed_pipe_ends_quietly():
    """``randvib power ... | head`` with the reader gone: no traceback, SIGPIPE's status."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run(
            [sys.executable, "-c", "import sys; from randvib.cli import main; sys.exit(main())"]
            + ["power", "--preset", "figure9", "--psd", "0.1:1:40"],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
            timeout=120,
        )
    finally:
        os.close(write_end)
    assert done.returncode == 141 and done.stderr == "", done.stderr


def test_messages_name_commands_not_functions():
    assert cli_wording("use randvib.simulate for this") == "use `randvib simulate` for this"
    assert cli_wording("see `randvib.predict()`") == "see `randvib power`"
    assert cli_wording("randvib.Harvester stays") == "randvib.Harvester stays"
    assert cli_wording("Use method='fpk-fast' there") == "Use `--method fpk-fast` there"


def test_compile_notice_once_on_a_cache_miss(capsys):
    with compile_notice():
        numba.njit(lambda x: x + 1)(1)  # a new function: compiled, never cached
        numba.njit(lambda x: x + 2)(1)
    assert capsys.readouterr().err.count(COMPILING) == 1
    with compile_notice():
        pass  # nothing compiled: nothing said
    assert COMPILING not in capsys.readouterr().err


def test_step_warning_is_one_readable_line(capsys):
    code, out, err = run(
        capsys,
        "simulate",
        "--preset",
        "figure9",
        "--psd",
        "1",
        "--paths",
        "4",
        "--t-end",
        "0.3",
        "--burn-in",
        "0.1",
        "--dt",
        "2e-4",
        "--method",
        "euler-maruyama",
    )
    assert code == 0
    (line,) = [text for text in err.splitlines() if "warning" in text]
    assert line.startswith("randvib simulate: warning: --dt = 0.0002 s gives euler-maruyama")
    assert "use --dt <= " in line and ".py" not in line


# ------------------------------------------------------------- output for people
def test_estimate_shown_to_its_interval():
    assert format_estimate(0.0024619412547950926, 0.000272784) == ("0.00246", "0.00027")
    assert format_estimate(12345.678, 140.0) == ("12350", "140")
    assert format_estimate(0.99, 0.0996) == ("0.99", "0.10")  # 0.0996 rounds up a place
    assert format_estimate(-1e-9, 1e-3) == ("0.0000", "0.0010")  # never "-0"


def test_simulate_prints_device_and_excitation(capsys):
    argv = ["simulate", "--preset", "figure9", "--psd", "1", "--excitation", "band-pass"]
    argv += ["--f0", "8", "--zeta", "0.2", "--paths", "4", "--t-end", "0.3", "--burn-in", "0.1"]
    code, out, _ = run(capsys, *argv)
    assert code == 0
    assert "device: m 0.0226 kg" in out and "coulomb friction (fc 0.0058 N)" in out
    assert "excitation: band-pass (level 1 (m/s^2)^2/Hz, f0 8 Hz, zeta 0.2)" in out


def test_power_without_coil_says_why_and_reports_mechanical(capsys):
    code, out, _ = run(capsys, "power", "--preset", "coulomb-td1", "--psd", "1")
    assert code == 0 and "no electrical damping (c_e = 0" in out and "--c-e" in out
    code, out, _ = run(capsys, "power", "--preset", "coulomb-td1", "--psd", "1", "--json")
    data = json.loads(out)
    assert data["power_electrical"] == 0
    # under white noise all that is dissipated is m S / 4 (c_eq = S m / (4 E[v^2]))
    assert data["power_mechanical"] == pytest.approx(0.0226 * 1.0 / 4, rel=1e-12)


@pytest.mark.parametrize("method", ["linearisation", "averaging"])
def test_power_mechanical_closes_the_energy_balance(capsys, method):
    code, out, _ = run(
        capsys, "power", "--preset", "figure9", "--psd", "0.5", "--json", "--method", method
    )
    data = json.loads(out)
    total = data["power_mechanical"] + data["power_electrical"]
    assert total == pytest.approx(FIG9.m * 0.5 / 4, rel=1e-12)
    assert data["power_mechanical"] > data["power_electrical"]  # friction dissipates too


# ------------------------------------------------------------- power sweeps
def test_sweep_values():
    assert sweep_values("0:0.05:11") == pytest.approx(np.linspace(0, 0.05, 11), abs=1e-15)
    assert sweep_values("2.5") == [2.5]
    for bad in ("0:1", "0:1:1", "0:1:x", "a", "0:inf:3"):
        with pytest.raises(argparse.ArgumentTypeError):
            sweep_values(bad)


def test_power_sweep_json_is_the_single_points(capsys):
    code, out, _ = run(
        capsys, "power", "--preset", "figure9", "--psd", "1", "0.5", "--fc", "0:0.01:3", "--json"
    )
    points = json.loads(out)
    assert code == 0 and len(points) == 6
    for fc, psd, point in zip([0, 0, 0.005, 0.005, 0.01, 0.01], [1, 0.5] * 3, points, strict=True):
        expected = rv.predict(FIG9.updated(fc=fc), psd)
        assert point["psd"] == psd and point["power_electrical"] == expected.power_electrical


def test_power_sweep_table_and_csv(capsys, tmp_path):
    target = tmp_path / "sweep.csv"
    argv = ["power", "--preset", "figure9", "--psd", "1", "0.5", "0.1", "--csv", target]
    code, out, _ = run(capsys, *argv)
    assert code == 0 and "swept --psd" in out and f"wrote {target} (3 points)" in out
    with open(target, newline="") as file:
        rows = list(csv.DictReader(file))
    assert [float(r["psd"]) for r in rows] == [1, 0.5, 0.1]
    for row in rows:
        assert float(row["power_electrical"]) == rv.expected_power(FIG9, float(row["psd"]))
    one_line_error(capsys, argv, "exists")  # a new file unless --force
    assert run(capsys, *argv, "--force")[0] == 0


def test_power_sweep_bad_range_is_one_line(capsys):
    one_line_error(capsys, ["power", "--preset", "figure9", "--psd", "1:0.1"], "START:STOP:COUNT")


def test_optimal_load(capsys):
    code, out, _ = run(capsys, "power", *WIRED_ARGS, "--psd", "1", "--optimal-load", "--json")
    data = json.loads(out)
    r_load, power = rv.optimal_load_resistance(WIRED, 1.0)
    assert data["r_load_optimal"] == r_load and data["power_load_optimal"] == power
    one_line_error(
        capsys, ["power", "--preset", "figure9", "--psd", "1", "--optimal-load"], "coupling"
    )


# ------------------------------------------------------------- arrays
ARRAY = np.array([1.0, 0.1])


@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda: rv.optimal_load_resistance(WIRED, ARRAY), "`psd` must be one number"),
        (lambda: rv.simulate(FIG9, ARRAY, t_end=0.2, dt=1e-4, n_paths=2), "`psd` must be one"),
        (lambda: rv.statistical_linearisation(FIG9, ARRAY), "`psd` must be one number"),
        (lambda: BandLimited(ARRAY, 4, 20), "`level` must be one number"),
        (
            lambda: rv.simulate(FIG9.updated(fc=ARRAY), 1.0, t_end=0.2, dt=1e-4, n_paths=2),
            "simulate needs scalar harvester parameters \\(one device\\): `fc`",
        ),
        (
            lambda: rv.statistical_linearisation(FIG9.updated(fc=ARRAY), 1.0),
            "statistical_linearisation needs scalar harvester parameters",
        ),
        (lambda: BandLimited(1.0, 4, ARRAY * 30), "`f_hi` must be one number"),
        (
            lambda: rv.synthetic_record(
                FIG9.updated(c_m=ARRAY), 1.0, duration=1.0, sample_rate=1000
            ),
            "synthetic_record needs scalar harvester parameters \\(one device\\): `c_m`",
        ),
        (
            lambda: rv.optimal_load_resistance(WIRED.updated(c_m=ARRAY), 1.0),
            "optimal_load_resistance needs scalar harvester",
        ),
    ],
)
def test_arrays_refused_by_name(call, fragment):
    with pytest.raises(ValueError, match=fragment.replace("`", ".")):
        call()


@pytest.mark.parametrize("method", ["linearisation", "averaging", "fpk-fast"])
def test_arrays_broadcast_where_documented(method):
    both = rv.predict(FIG9, ARRAY, method=method)
    for i, psd in enumerate(ARRAY):
        one = rv.predict(FIG9, float(psd), method=method)
        assert both.power_electrical[i] == pytest.approx(one.power_electrical, rel=1e-12)
    assert rv.expected_power(FIG9, ARRAY)[1] == pytest.approx(
        rv.expected_power(FIG9, 0.1), rel=1e-12
    )
    assert rv.equivalent_damping(FIG9, ARRAY)[0] == pytest.approx(
        rv.equivalent_damping(FIG9, 1.0), rel=1e-12
    )


def test_every_error_line_names_its_command(capsys):
    """Parser and command errors read alike: ``randvib COMMAND: error: ...``."""
    one_line_error(
        capsys, ["power", "--psd", "1", "--nosuch"], "randvib power: error: unrecognized"
    )
    one_line_error(capsys, ["power", "--friction", "x"], "randvib power: error: `--friction`")
    one_line_error(capsys, ["power", "--friction", "lugre", "--psd", "1"], "randvib power: error:")
    one_line_error(capsys, ["bogus"], "randvib: error: `COMMAND` must be one of power")


def test_table_columns_of_words_are_flush_left_and_named(capsys):
    from randvib.cli._output import print_table

    print_table(
        [["c", 0.049, 1e-3, "Ns/m", "identified"], ["m", 0.0226, None, "kg", "fixed"]],
        ["parameter", "value", "std. error", "unit", "status"],
    )
    header, rule, first, second = capsys.readouterr().out.splitlines()
    assert header.split() == ["parameter", "value", "std.", "error", "unit", "status"]
    # words start where their header starts; numbers end where theirs ends
    assert first.index("Ns/m") == header.index("unit") == second.index("kg")
    assert first.index("identified") == header.index("status") == second.index("fixed")
    assert first.index("0.049") + len("0.049") == header.index("value") + len("value")


def test_identify_table_shows_the_digits_the_standard_error_supports():
    row = with_standard_error(57.4001412, 0.00014079, (57.3998653, 57.4004171))
    assert row == ["57.40014", "0.00014", "[57.39987, 57.40042]"]
    # a noise-free fit: eight significant digits, the tiny error in exponent form
    assert with_standard_error(0.0490000000112, 2.09e-12, None) == ["0.049000000", "2.1e-12", ""]
    assert with_standard_error(0.0226, None, None) == ["0.0226", "", ""]  # a fixed parameter


def test_degenerate_values_name_the_option_the_user_gave(capsys, tmp_path):
    """`record --psd 0` names `--psd` (not the band's `level`); an empty `--rows` range names it."""
    out = tmp_path / "r.csv"
    one_line_error(capsys, ["record", "--preset", "coulomb-td1", "--psd", "0", "--out", out],
                   "`--psd` must be > 0")  # fmt: skip
    assert not out.exists()
    code, _, err = run(capsys, "record", "--preset", "coulomb-td1", "--psd", 1, "--duration", 1,
                       "--out", out)  # fmt: skip
    assert code == 0, err
    for rows in ("10:2", "1000:", "-1:5"):
        one_line_error(capsys, fit_args(out, "--rows", rows), f"`--rows` = {rows} selects none")


def test_refused_sweep_point_is_one_line_without_another_points_advice(capsys):
    """Advice about a finished point is held until the sweep is done, dropped if it is refused."""
    base = ["power", "--preset", "coulomb-td1", "--c-m", 5e-4, "--c-e", 5e-4, "--psd", 5e-3]
    # fc = 5.8 mN: friction takes 99.9 % of the dissipation (advice); fc = 5e299 N: refused
    one_line_error(capsys, [*base, "--fc", "0.0058:1e300:3"], "fc = 5e+299 is beyond the range")
    code, out, err = run(capsys, *base, "--fc", "0.0058:0.006:2")
    assert code == 0 and err.count("warning: friction takes") == 1, err


# ----------------------------------------------------- help and compiling (issue 35, 12 and 15)
def test_help_lists_the_commands_without_importing_them():
    """`randvib --help` imported the whole package (4.7-6 s): it now imports no command,
    hence neither numba, scipy nor pandas; the list names every command with its line."""
    probe = (
        "import sys\nfrom randvib.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "print(sorted(m for m in ('numba', 'scipy', 'pandas', 'matplotlib') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False, cwd=ROOT)  # fmt: skip
    assert done.returncode == 0, done.stderr
    out = done.stdout.splitlines()
    assert out[-1] == "[]", done.stdout
    from randvib.cli import COMMAND_HELP

    text = "\n".join(out)
    for name in COMMAND_HELP:
        assert name in text
    # the one-line help of each command's own parser is the list's
    for name, parser in subcommands().items():
        choice = next(a for a in build_parser()._actions if a.dest == "command")
        helps = {c.dest: c.help for c in choice._choices_actions}
        assert helps[name] == COMMAND_HELP[name], name
        assert parser.prog == f"randvib {name}"


def test_a_commands_help_is_kept_and_printed_without_building_the_parser(capsys, monkeypatch):
    """`randvib COMMAND --help` is built once, kept beside the package's bytecode (keyed by
    the sources and the terminal's width), then printed without importing the command."""
    import randvib.cli as cli
    from randvib.cli import _help

    # _help.shutil is the global module: pytest's own terminal calls it, with fallback=
    monkeypatch.setattr(
        _help.shutil, "get_terminal_size", lambda *a, **k: os.terminal_size((97, 40))
    )
    _help._path("record").unlink(missing_ok=True)
    with pytest.raises(SystemExit):
        cli.main(["record", "--help"])
    built = capsys.readouterr().out
    assert built.startswith("usage: randvib record") and _help.kept_help("record") == built

    def no_parser(*args, **kwargs):
        raise AssertionError("the parser was built")

    monkeypatch.setattr(cli, "build_parser", no_parser)
    with pytest.raises(SystemExit) as kept:  # as argparse's --help ends: the same either way
        cli.main(["record", "--help"])
    assert kept.value.code == 0 and capsys.readouterr().out == built
    monkeypatch.setattr(
        _help.shutil, "get_terminal_size", lambda *a, **k: os.terminal_size((61, 40))
    )
    assert _help.kept_help("record") is None  # another width: built again
    _help._path("record").unlink(missing_ok=True)


def test_compile_says_what_it_compiled_and_what_it_loaded(capsys, monkeypatch):
    """`randvib compile` runs each group of kernels once and says, per group, whether it was
    compiled or loaded from the cache, and how long the whole took."""
    from randvib.cli import compile as compile_command

    steps = [("a new kernel", lambda: numba.njit(lambda x: x * 3)(1)), ("nothing", lambda: None)]
    monkeypatch.setattr(compile_command, "warm_up_steps", lambda: steps)
    code, out, err = run(capsys, "compile")
    assert code == 0 and COMPILING not in err, err
    lines = out.splitlines()
    assert lines[0] == "compiling randvib's numerical kernels (2 groups; once per install)"
    assert lines[1].startswith("  [1/2] a new kernel: 1 compiled, ")
    assert lines[2].startswith("  [2/2] nothing: loaded from the cache, ")
    assert lines[3].startswith("done in ") and "1 function(s) compiled" in lines[3]


def test_design_takes_segments_for_a_record_only(capsys, monkeypatch, tmp_path):
    """`--segments` (the windows of a record, the Monte Carlo paths) was missing from
    `design`: passed to rv.design with --record, refused without one."""
    one_line_error(capsys, ["design", "--preset", "figure9", "--psd", "1", "--stroke", "0.005",
                            "--vary", "k=40:80", "--segments", "4"],
                   "`--segments` cuts a record into paths; it needs `--record`")  # fmt: skip
    import randvib.cli.design as design_command

    seen = {}

    def fake_design(*args, **kwargs):
        seen.update(kwargs)
        raise ValueError("stop here")

    monkeypatch.setattr(design_command, "design", fake_design)
    t = np.arange(2000) * 1e-3
    path = tmp_path / "record.csv"
    rv.Record(time=t, base_acceleration=np.sin(2 * np.pi * 8 * t)).to_csv(path)
    code, out, err = run(capsys, "design", "--preset", "figure9", "--record", path,
                         "--stroke", "0.005", "--vary", "k=40:80", "--segments", "4")  # fmt: skip
    assert code == 2 and "stop here" in err and seen["segments"] == 4
