"""Fuzzing the command line and the public functions.

Hypothesis draws arguments, ordinary and extreme (0, +-1e308, 1e-308, NaN,
inf, huge integers), and each test asserts the contract: a command ends with
exit 0 and finite numbers in valid JSON, or exit 2 with one line on stderr;
never a traceback, an internal error (exit 1) or a non-finite number with
exit 0. Sizes are bounded so that no legitimate run is long (a hang would
show as the test's own timeout).

Covers every command of :mod:`randvib.cli` and
:func:`randvib.analytic.prediction.predict`.
"""

import json
import math

import numpy as np
import pytest
from _cli import error_lines
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import randvib as rv
from randvib.cli import main

EXTREMES = [0.0, -0.0, 1e-308, -1e-308, 1e308, -1e308, 1e-30, 1e30, math.nan, math.inf, -math.inf]
#: Valid but extreme values, the ones that overflow float64 inside a method.
HUGE_OR_TINY = [1e308, 1e300, 1e200, 1e-200, 1e-300, 1e-308]


def numbers(lo, hi):
    """Ordinary values in [lo, hi], negatives and the extremes."""
    return st.one_of(
        st.floats(lo, hi),
        st.floats(-hi, -lo),
        st.sampled_from(EXTREMES),
    )


def devices(**ranges):
    """Parameter dicts: ordinary values, with one or two of them replaced by an extreme.

    (Drawing every parameter from :func:`numbers` would almost never give a
    device that is valid but for one extreme value, the case that overflows.)
    """
    ordinary = st.fixed_dictionaries({n: st.floats(lo, hi) for n, (lo, hi) in ranges.items()})
    extreme = st.dictionaries(
        st.sampled_from(sorted(ranges)),
        st.one_of(st.sampled_from(EXTREMES), st.sampled_from(HUGE_OR_TINY)),
        min_size=0,
        max_size=2,
    )
    return st.builds(lambda a, b: {**a, **b}, ordinary, extreme)


def _run(capsys, argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _check_contract(code, out, err, json_out: bool):
    assert code in (0, 2), (code, err)
    assert "Traceback" not in err
    if code == 2:
        assert len(error_lines(err)) == 1, err
        return
    if json_out:
        data = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in JSON output"))
        _assert_finite(data)
    else:
        for word in ("nan", "inf"):
            assert word not in out.lower().replace("info", ""), out


def _assert_finite(value):
    if isinstance(value, dict):
        for v in value.values():
            _assert_finite(v)
    elif isinstance(value, list):
        for v in value:
            _assert_finite(v)
    elif isinstance(value, float):
        assert math.isfinite(value)


FUZZ = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@FUZZ
@given(
    p=devices(
        m=(1e-3, 1.0), c_m=(0.0, 1.0), k=(1.0, 1e3), k3=(0.0, 1e6), fc=(0.0, 0.1), psd=(1e-3, 10.0)
    ),  # fmt: skip
    method=st.sampled_from(["linearisation", "averaging", "fpk-fast"]),
    json_out=st.booleans(),
)
def test_power_cli_contract(capsys, p, method, json_out):
    argv = ["power", "--preset", "figure9", "--method", method]
    argv += [f"--{name.replace('_', '-')}={value}" for name, value in p.items()]
    if json_out:
        argv.append("--json")
    _check_contract(*_run(capsys, argv), json_out)


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    p=devices(m=(1e-3, 1.0), k3=(0.0, 1e6), psd=(1e-3, 10.0), fc=(0.0, 0.1)),
    dt=st.one_of(st.floats(2e-5, 1e-2), st.sampled_from([0.0, -1e-4, 1e308, math.nan])),
    paths=st.one_of(st.integers(-2, 4), st.sampled_from([2**63, 10**30])),
    seed=st.one_of(st.integers(-5, 5), st.sampled_from([2**64 - 1, 2**64, -(2**70)])),
)
def test_simulate_cli_contract(capsys, p, dt, paths, seed):
    argv = ["simulate", "--preset", "figure9", f"--dt={dt}", f"--paths={paths}",
            f"--seed={seed}", "--t-end=0.05", "--burn-in=0.01", "--json"]  # fmt: skip
    argv += [f"--{name}={value}" for name, value in p.items()]
    _check_contract(*_run(capsys, argv), True)


@pytest.fixture(scope="module")
def record_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    record = rv.synthetic_record(
        rv.preset("coulomb-td1"), 2.0, duration=0.5, sample_rate=1000.0, seed=2
    )
    record.to_csv(folder / "rec.csv", float_format=None)
    params = folder / "p.json"
    params.write_text(
        json.dumps(
            {
                "model": "coulomb",
                "parameters": {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 70742.0, "fc": 0.0058},
            }
        )
    )
    return folder / "rec.csv", params


@FUZZ
@given(
    skip=st.integers(-10, 1000),
    substeps=st.integers(-3, 16),
    name=st.sampled_from(["m", "c", "k", "k3", "fc", "beta", "bogus"]),
    value=numbers(1e-3, 1e5),
    lowpass=st.one_of(st.none(), numbers(1.0, 400.0)),
)
def test_validate_cli_contract(capsys, record_files, skip, substeps, name, value, lowpass):
    rec, params = record_files
    argv = ["validate", params, rec, f"--skip={skip}", f"--substeps={substeps}",
            "--set", f"{name}={value}", "--json"]  # fmt: skip
    if lowpass is not None:
        argv.append(f"--lowpass={lowpass}")
    _check_contract(*_run(capsys, argv), True)


@settings(max_examples=300, deadline=None)
@given(
    p=devices(
        m=(1e-3, 1.0), c_m=(0.0, 1.0), k=(1.0, 1e3), k3=(0.0, 1e6), fc=(0.0, 0.1), psd=(1e-3, 10.0)
    ),  # fmt: skip
    method=st.sampled_from(["linearisation", "averaging", "fpk-fast"]),
)
def test_predict_refuses_or_is_finite(p, method):
    p = dict(p)
    try:
        friction = rv.Coulomb(fc=p.pop("fc"))
        psd = p.pop("psd")
        device = rv.Harvester(c_e=0.1, friction=friction, **p)
        result = rv.predict(device, psd, method)
    except ValueError:
        return  # refused with a message: allowed
    if device.potential.is_free:  # the free mass: no stationary displacement, reported as None
        assert result.displacement_variance is None, result
    else:
        assert math.isfinite(result.displacement_variance), result
        assert result.displacement_variance > 0, result
    for name in ("velocity_variance", "power_electrical"):
        assert math.isfinite(getattr(result, name)), (name, result)
    assert result.velocity_variance > 0, result


# ---------------------------------------------------------- excitation and coupling options
#: Each excitation with the options it takes, and the ordinary range of each.
EXCITATION_OPTIONS = {
    "white": {},
    "band-pass": {"f0": (1.0, 100.0), "zeta": (0.01, 1.0)},
    "kanai-tajimi": {"f0": (1.0, 100.0), "zeta": (0.01, 1.0)},
    "band-limited": {"f_lo": (0.0, 10.0), "f_hi": (20.0, 200.0)},
}
#: Each coupling with the options it takes, and the ordinary range of each.
COUPLING_OPTIONS = {
    None: {},
    "resistive": {"alpha": (1.0, 50.0), "r_load": (10.0, 1e3), "r_coil": (1.0, 100.0)},
    "inductive": {
        "alpha": (1.0, 50.0),
        "r_load": (10.0, 1e3),
        "r_coil": (1.0, 100.0),
        "inductance": (1e-4, 1.0),
    },  # fmt: skip
    "piezo": {"theta": (1e-4, 1e-2), "capacitance": (1e-9, 1e-6), "r_load": (1e3, 1e6)},
}
#: Extreme values of the new options (zero, negative, overflow, underflow).
NEW_EXTREMES = [0.0, -1.0, -1e308, 1e308, 1e-308, -1e-308, math.nan, math.inf]


def _option_values(ranges: dict):
    """Ordinary values of the given options, up to two replaced by an extreme."""
    if not ranges:
        return st.just({})
    ordinary = st.fixed_dictionaries({n: st.floats(lo, hi) for n, (lo, hi) in ranges.items()})
    extreme = st.dictionaries(
        st.sampled_from(sorted(ranges)), st.sampled_from(NEW_EXTREMES), max_size=2
    )
    return st.builds(lambda a, b: {**a, **b}, ordinary, extreme)


@st.composite
def excitation_and_coupling(draw):
    """argv fragments: an excitation, a coupling, k (negative: bistable), k3, stroke."""
    argv = []
    excitation = draw(st.sampled_from(sorted(EXCITATION_OPTIONS)))
    argv += ["--excitation", excitation]
    for name, value in draw(_option_values(EXCITATION_OPTIONS[excitation])).items():
        argv.append(f"--{name.replace('_', '-')}={value}")
    coupling = draw(st.sampled_from(list(COUPLING_OPTIONS)))
    if coupling is not None:
        argv += ["--coupling", coupling]
        for name, value in draw(_option_values(COUPLING_OPTIONS[coupling])).items():
            argv.append(f"--{name.replace('_', '-')}={value}")
    device = draw(_option_values({"k": (-200.0, 200.0), "k3": (0.0, 1e7), "stroke": (1e-3, 0.1)}))
    argv += [f"--{name}={value}" for name, value in device.items()]
    return argv


@FUZZ
@given(extra=excitation_and_coupling(), json_out=st.booleans())
def test_power_cli_contract_new_options(capsys, extra, json_out):
    argv = ["power", "--preset", "figure9", "--psd=1.0", *extra] + (["--json"] if json_out else [])
    _check_contract(*_run(capsys, argv), json_out)


@settings(
    max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(extra=excitation_and_coupling())
def test_simulate_cli_contract_new_options(capsys, extra):
    argv = ["simulate", "--preset", "figure9", "--psd=1.0", "--paths=2", "--dt=2e-4",
            "--t-end=0.05", "--burn-in=0.01", "--json", *extra]  # fmt: skip
    _check_contract(*_run(capsys, argv), True)


BAD_TABLES = {
    "empty.csv": "",
    "header_only.csv": "frequency,psd\n",
    "one_row.csv": "frequency,psd\n10,1\n",
    "negative.csv": "frequency,psd\n1,1\n10,-1\n20,1\n",
    "nan.csv": "frequency,psd\n1,1\n10,nan\n20,1\n",
    "huge.csv": "frequency,psd\n1,1e308\n10,1e308\n20,1e308\n",
    "unsorted.csv": "frequency,psd\n20,1\n1,1\n10,1\n",
    "duplicate.csv": "frequency,psd\n1,1\n1,2\n20,1\n",
    "zero.csv": "frequency,psd\n1,0\n10,0\n20,0\n",
    "text.csv": "frequency,psd\n1,a\n10,b\n",
    "wrong_columns.csv": "f,S\n1,1\n10,1\n",
    "binary.csv": "\x00\x01\x02",
}
BAD_RECORDS = {
    "empty.csv": "",
    "header_only.csv": "time,base_acceleration\n",
    "short.csv": "time,base_acceleration\n0,1\n0.001,2\n",
    "uneven.csv": "time,base_acceleration\n" + "".join(f"{t**2 / 1e3},{math.sin(t)}\n" for t in range(50)),
    "constant.csv": "time,base_acceleration\n" + "".join(f"{t / 1e3},1\n" for t in range(200)),
    "huge.csv": "time,base_acceleration\n" + "".join(f"{t / 1e3},{1e300 * (-1) ** t}\n" for t in range(200)),
    "nan.csv": "time,base_acceleration\n" + "".join(f"{t / 1e3},nan\n" for t in range(200)),
    "backwards.csv": "time,base_acceleration\n" + "".join(f"{-t / 1e3},{t % 3}\n" for t in range(200)),
    "wrong_columns.csv": "t,a\n0,1\n0.001,2\n",
}  # fmt: skip


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bad_inputs")
    made = {}
    for kind, table in (("psd-file", BAD_TABLES), ("record", BAD_RECORDS)):
        (folder / kind).mkdir()
        for name, text in table.items():
            (folder / kind / name).write_text(text)
        made[kind] = [folder / kind / name for name in table]
        made[kind] += [folder / kind, folder / kind / "missing.csv"]  # a folder, no file
    return made


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    command=st.sampled_from(["power", "simulate"]),
    kind=st.sampled_from(["psd-file", "record"]),
    index=st.integers(0, 100),
)
def test_bad_psd_files_and_records_are_named(capsys, bad_files, command, kind, index):
    path = bad_files[kind][index % len(bad_files[kind])]
    argv = [command, "--preset", "figure9", f"--{kind}", path, "--json"]
    if command == "simulate":
        argv += ["--paths=2", "--t-end=0.05", "--burn-in=0.01"]
    code, out, err = _run(capsys, argv)
    _check_contract(code, out, err, True)
    if code == 2 and path.exists() and path.is_file():
        assert path.name in err or "psd" in err or "record" in err, err


# ------------------------------------------------------------------ new public functions
def _couplings():
    from randvib.models.coupling import Inductive, Piezo, Resistive

    return st.one_of(
        st.builds(lambda p: Resistive(**p), _option_values(COUPLING_OPTIONS["resistive"])),
        st.builds(lambda p: Inductive(**p), _option_values(COUPLING_OPTIONS["inductive"])),
        st.builds(lambda p: Piezo(**p), _option_values(COUPLING_OPTIONS["piezo"])),
    )


def _excitations():
    return st.one_of(
        st.builds(lambda p: rv.BandPass(level=1.0, **p), _option_values(EXCITATION_OPTIONS["band-pass"])),
        st.builds(lambda p: rv.KanaiTajimi(level=1.0, **p), _option_values(EXCITATION_OPTIONS["kanai-tajimi"])),
        st.builds(lambda p: rv.BandLimited(level=1.0, **p), _option_values(EXCITATION_OPTIONS["band-limited"])),
        st.sampled_from([1.0, 1e-300, 1e300]),
    )  # fmt: skip


def _refused(build):
    """``build()``, or None when it is refused with a ValueError (statistical
    linearisation that did not converge included)."""
    try:
        return build()
    except ValueError:
        return None


@settings(max_examples=25, deadline=None)
@given(
    p=_option_values({"m": (1e-3, 1.0), "c_m": (0.0, 1.0), "k": (-200.0, 200.0), "k3": (0.0, 1e7)}),
    coupling=st.data(),
    excitation=st.data(),
)
def test_coupled_linearisation_and_optimal_load_refuse_or_are_finite(p, coupling, excitation):
    """Harvester.with_coupling, statistical_linearisation and optimal_load_resistance
    with couplings: a ValueError naming the problem, or finite positive results."""
    c = _refused(lambda: coupling.draw(_couplings()))
    if c is None:
        return
    device = _refused(lambda: rv.Harvester.with_coupling(coupling=c, **p))
    if device is None:
        return
    psd = _refused(lambda: excitation.draw(_excitations()))
    if psd is None:
        return
    with np.errstate(all="ignore"):
        result = _refused(lambda: rv.statistical_linearisation(device, psd))
        if result is not None:
            for name in ("velocity_variance", "displacement_variance", "power_electrical"):
                value = getattr(result, name)
                assert math.isfinite(value) and value >= 0, (name, result)
        best = _refused(lambda: rv.optimal_load_resistance(device, psd))
    if best is not None:
        assert all(math.isfinite(x) and x > 0 for x in best), best


@settings(max_examples=200, deadline=None)
@given(k=numbers(1e-3, 1e4), k3=numbers(1e-3, 1e8))
def test_potential_refuses_or_is_finite(k, k3):
    from randvib.models.potential import Potential

    potential = _refused(lambda: Potential(k, k3))
    if potential is None:
        return
    with np.errstate(all="ignore"):
        for name in ("wells", "minimum", "barrier_height"):
            value = _refused(lambda name=name: getattr(potential, name))
            if value is not None:
                assert np.all(np.isfinite(np.asarray(value, dtype=float))), (name, value)


@pytest.fixture(scope="module")
def short_record():
    t = np.arange(2000) * 1e-3
    rng = np.random.default_rng(0)
    return t, rng.standard_normal(t.size)


@settings(max_examples=12, deadline=None)
@given(
    p=_option_values({"m": (1e-3, 1.0), "k": (1.0, 200.0), "k3": (0.0, 1e6)}),
    scale=st.sampled_from([1.0, 1e-300, 1e150, 1e300]),
    segments=st.sampled_from([2, 4, 1, 0]),
)
def test_monte_carlo_on_record_refuses_or_is_finite(short_record, p, scale, segments):
    t, a = short_record
    record = _refused(lambda: rv.Measured(rv.Record(time=t, base_acceleration=a * scale)))
    device = _refused(lambda: rv.preset("figure9").updated(**p))
    if record is None or device is None:
        return
    with np.errstate(all="ignore"):
        result = _refused(
            lambda: rv.monte_carlo_on_record(device, record, segments=segments, burn_in=0.2)
        )
    if result is not None:
        for name in ("power_electrical", "velocity_variance", "displacement_variance"):
            assert math.isfinite(getattr(result, name).mean), (name, result)


# --------------------------------------------------- issue 35, item 18: the new flags' crashes
BRIDGE_ARGS = ["--preset", "figure9", "--coupling", "inductive", "--rectifier", "bridge",
               "--alpha", "0.1992", "--r-coil", "0.48", "--battery", "0.02"]  # fmt: skip


@pytest.fixture(scope="module")
def event_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("events")
    (folder / "huge.csv").write_text("time,envelope\n0,0\n0.5,1e300\n1,0\n")
    (folder / "psd.csv").write_text("frequency,psd\n1,1\n10,1\n20,1\n")
    return folder


@pytest.mark.parametrize(
    "argv, flag",
    [
        # internal errors before (OverflowError, ZeroDivisionError, MemoryError)
        (["power", *BRIDGE_ARGS, "--psd", "1", "--v-diode", "1e300", "--optimal-load"], "--optimal-bounds"),
        (["power", *BRIDGE_ARGS, "--psd", "0", "--v-diode", "1e300", "--optimal-load"], "--psd"),
        (["simulate", "--preset", "figure9", "--psd", "1", "--envelope", "table", "--envelope-file",
          "{huge}", "--times", "0.5", "--paths", "4"], "--envelope-file"),
        (["simulate", "--preset", "figure9", "--psd", "1", "--envelope", "shinozuka-sato",
          "--envelope-a", "1e300", "--envelope-b", "1", "--envelope-c", "2", "--times", "0.5",
          "--paths", "4"], "--envelope-a"),
        (["simulate", "--preset", "figure9", "--psd", "1", "--envelope", "step", "--times", "1e9",
          "--paths", "4"], "--t-end"),
        (["simulate", "--preset", "figure9", "--psd", "1", "--envelope", "shinozuka-sato",
          "--envelope-b", "1e-310", "--envelope-c", "1e-309", "--times", "0.5", "--paths", "4"],
         "--envelope-b"),
        (["power", "--preset", "figure9", "--coupling", "inductive", "--rectifier", "bridge",
          "--alpha", "1e200", "--r-coil", "1e-200", "--battery", "0.02", "--psd", "1"], "--alpha"),
        # refused without naming a flag before (the design's infeasible budget)
        (["design", "--preset", "figure9", "--psd", "1", "--stroke", "0.005", "--vary", "k=40:80",
          "--no-monte-carlo", "--no-progress", "--exceedance", "1e-300"], "--exceedance"),
        # ran without end before
        (["design", "--preset", "figure9", "--psd", "1", "--stroke", "0.005", "--vary", "k=40:80",
          "--precision", "1e-300"], "--precision"),
    ],
)  # fmt: skip
def test_new_flags_at_extreme_values_are_refused_in_one_line_naming_the_flag(
    capsys, event_files, argv, flag
):
    argv = [a.format(huge=event_files / "huge.csv") for a in argv]
    code, out, err = _run(capsys, argv)
    _check_contract(code, out, err, False)
    assert code == 2 and f"`{flag}" in err, err
    if flag == "--exceedance":  # the budget is the stroke's, in the ranges varied
        assert "`--stroke` = 0.005 m" in err and "(`--vary`)" in err, err


def test_a_unit_peak_envelope_with_rates_far_apart_peaks_at_one():
    """The peak time log(c / b) / (c - b) overflowed for b near float64's smallest (c / b
    beyond float64) and the amplitude came out 0; as log c - log b it is finite."""
    envelope = rv.ShinozukaSato.unit_peak(1e-320, 1.0)
    t_peak = envelope.peak_time
    assert t_peak == pytest.approx(-np.log(1e-320), rel=1e-12)  # log(c / b) / (c - b), c = 1
    assert envelope.peak == pytest.approx(1.0, rel=1e-12)


def test_valid_extremes_of_the_new_flags_run_and_are_finite(capsys, event_files):
    """A tabulated spectrum through an event printed JSON that could not be written
    (Tabulated is not JSON); a stroke of 1e300 m overflowed the design's limit and first
    passage: both are valid requests with finite answers."""
    argv = ["simulate", "--preset", "figure9", "--psd-file", event_files / "psd.csv",
            "--envelope", "step", "--times", "0.05", "--paths", "4", "--dt", "1e-3", "--json"]  # fmt: skip
    code, out, err = _run(capsys, argv)
    _check_contract(code, out, err, True)
    assert code == 0 and json.loads(out)["psd"] is None  # a table has no single level
    argv = ["design", "--preset", "figure9", "--psd", "1", "--excitation", "band-pass",
            "--f0", "8", "--zeta", "0.2", "--stroke", "1e300", "--vary", "k=40:80",
            "--no-monte-carlo", "--json"]  # fmt: skip
    code, out, err = _run(capsys, argv)
    _check_contract(code, out, err, True)
    data = json.loads(out)
    assert code == 0 and data["stroke_exceedance_predicted"] == 0.0 and data["limit"] > 0


def test_a_closure_too_stiff_to_finish_is_stopped_and_refused(capsys, monkeypatch):
    """`power --psd 1e-300 --envelope shinozuka-sato` ran without end (the friction's
    equivalent damping against a vanishing input: a stiffness the solver crawls through).
    The moment equations are stopped after a bounded number of evaluations (here lowered,
    so that the test is quick) and refused naming Monte Carlo."""
    from randvib.analytic import transient

    monkeypatch.setattr(transient, "MAX_EVALUATIONS", 3000)
    monkeypatch.setattr(transient, "MAX_EVALUATIONS_PER_SECOND", 500)
    argv = ["power", "--preset", "figure9", "--psd", "1e-300", "--envelope", "shinozuka-sato",
            "--envelope-b", "0.5", "--envelope-c", "2", "--t-end", "6"]  # fmt: skip
    code, out, err = _run(capsys, argv)
    _check_contract(code, out, err, False)
    assert code == 2 and "stopped at t = " in err and "randvib simulate --envelope" in err
