"""Identification of friction models and the CLI commands identify and validate.

Covers randvib.identification.identify (the driver), .cost (Eq. 11), .bounds,
.settings, .models, .result and .prediction (predict_record, validate).

Covers :func:`randvib.identify` and its parts: :mod:`randvib.identification.identify`,
:mod:`randvib.identification.cost`, :mod:`randvib.identification.bounds`,
:mod:`randvib.identification.settings`, :mod:`randvib.identification.result` and
:mod:`randvib.identification.prediction`.
"""

import json
from types import SimpleNamespace

import _identification as H
import numpy as np
import pytest
from _stats import assert_matches

import randvib as rv
from randvib.cli import main
from randvib.identification.bounds import default_bounds
from randvib.identification.cost import CostFunction, initial_velocity, normalised_cost
from randvib.identification.identify import identify
from randvib.identification.models import MeasurementModel
from randvib.identification.prediction import predict_record, validate
from randvib.identification.record_response import record_response
from randvib.identification.settings import SearchSettings, SimulationSettings
from randvib.models.excitation import band_limited_excitation
from randvib.models.record import Record

COULOMB = H.COULOMB
TRUE = COULOMB


def synthetic(
    seed=0, rms=1.07, duration=3.0, fs=500.0, kind="base_displacement", model="coulomb", params=TRUE
):
    ex = band_limited_excitation(duration, fs, rms, seed=seed)
    device = H.harvester(params, model)
    z = record_response(device, ex, input_kind="base_acceleration", substeps=8).z[0]
    return Record(1 / fs, name=f"test{seed}", relative_displacement=z, **{kind: ex[kind]})


@pytest.fixture(scope="module")
def record():
    return synthetic(kind="base_acceleration")


def test_cost_is_eq11():
    z = np.array([1.0, 2.0, 3.0, 4.0])
    assert normalised_cost(z, np.full(4, z.mean())) == pytest.approx(100.0)  # Eq. 12
    assert normalised_cost(z, z) == 0.0
    assert normalised_cost(z, z + 0.1) == pytest.approx(100 * 0.01 / np.var(z))


def test_search_cost_is_eq11_of_predict_record(record):
    """The compiled batch cost SaDE minimises is J (Eq. 11) of predict_record, to rounding.

    The reported J comes from predict_record or the polish, so only this
    comparison sees a mis-scaled search cost (its SaDE history is what
    figure 7 plots). Away from the optimum, so that J is not ~0.
    """
    fixed = {**NO_OFFSETS, "m": COULOMB["m"]}
    free = ("c", "k", "k3", "fc")
    x = [COULOMB["c"] * 1.02, COULOMB["k"] * 0.99, COULOMB["k3"] * 1.03, COULOMB["fc"] * 0.95]
    search_cost = CostFunction(record, "coulomb", fixed=fixed, free=free, initial_state="record")
    parameters = {**fixed, **dict(zip(free, x, strict=True))}
    expected = predict_record(
        H.harvester(parameters),
        record,
        measurement=H.measurement(parameters),
        initial_state="record",
    ).cost
    assert expected > 0.1  # far from the optimum
    assert search_cost(np.array([x]))[0] == pytest.approx(expected, rel=1e-9)


#: Relative precision (of each identified parameter, after the linearised offset
#: of the optimum is removed) that SaDE + Nelder-Mead polish must reach on a
#: noise-free record: 90 times below the 0.9 % error of a mis-scaled mass.
#: Seed study (optimiser seeds 0-7, Coulomb record not at rest): popsize 30 x
#: 80 generations reached <= 1.1e-7 in 7 seeds and 1.7e-4 in one (seed 3,
#: polish stopped by its evaluation budget); popsize 16 x 40 failed in 4 of 8
#: (up to a local minimum with J = 0.02), so the tests use 30 x 80 for
#: Coulomb. The tanh and LuGre budgets below were checked with seed 1 only.
TOL = 1e-4
#: An initial state far from rest: about 1.4 z_rms and 0.8 v_rms.
Z0, V0 = 1e-3, 0.03


#: The measurement model the error models of these tests (tests/_identification.py)
#: are built on: the simulation starts from the record's first samples and the
#: sensors have no offsets. The estimated start and offsets (the defaults) are
#: tested in tests/test_measurement_model.py.
NO_OFFSETS = {"input_offset": 0.0, "output_offset": 0.0}


def identify_classic(rec, model, *, fixed=None, **kwargs):
    """identify with the start taken from the record and no offsets estimated,
    the input reconstructed linearly as the records here were simulated."""
    kwargs.setdefault("hold", "linear")
    return identify(
        rec, model, fixed={**NO_OFFSETS, **(fixed or {})}, initial_state="record", **kwargs
    )


def assert_at_optimum(res, truth, lin, what):
    err = np.array([np.log(res.parameters[n] / truth[n]) for n in lin.free])
    off = err - lin.bias
    assert np.all(np.abs(off) <= TOL), (
        f"{what}: ln(theta/true) - bias = {dict(zip(lin.free, off, strict=True))}"
    )


def not_at_rest(model, params, *, seed=0, duration=1.5, fs=500.0):
    ex = H.excitation(seed, duration, fs)
    z, _ = H.clean_response(params, model, ex, z0=Z0, v0=V0)
    return H.make_record(ex, z, name=f"{model}{seed}")


def test_initial_velocity_is_the_fourth_order_one_sided_stencil():
    dt = 0.01
    t = np.arange(5) * dt
    quartic = 0.3 - 2.0 * t + 5.0 * t**2 - 7.0 * t**3 + 11.0 * t**4
    assert initial_velocity(quartic, dt) == pytest.approx(-2.0, rel=1e-12)  # exact to t^4
    z = np.random.default_rng(0).standard_normal(5)
    assert initial_velocity(z, dt) == pytest.approx(H.VELOCITY_STENCIL @ z / dt, rel=1e-12)


@pytest.mark.parametrize("skip", [0, 40])
def test_true_parameters_score_the_residual_of_the_initial_state(skip):
    """J of the truth on a record not at rest equals Eq. 11 of the independent residual.

    The reference starts the simulation, like identify, from the first sample
    and the stencil velocity (re-implemented in tests/_identification.py) and
    scores the samples from ``skip`` on. What remains is the stencil's
    truncation error (J ~ 1e-8): starting from rest instead gives J ~ 100.
    """
    rec = not_at_rest("coulomb", COULOMB)
    z0, v0 = H.initial_state(rec.z, rec.dt)
    zhat = H.sensitivities(COULOMB, "coulomb", rec, (), z0, v0)[0]
    r = (rec.z - zhat)[skip:]
    reference = 100 * np.mean(r**2) / np.var(rec.z[skip:])
    assert reference < 1e-6
    device = H.harvester(COULOMB)
    assert predict_record(device, rec, skip=skip, initial_state="record").cost == pytest.approx(
        reference, rel=1e-6
    )
    # the device's own (zero) offsets: this is about the start, not the offsets
    (row,) = validate(device, [rec], skip=skip, initial_state="record", offsets="given")
    assert row.cost == pytest.approx(reference, rel=1e-6)


@pytest.fixture(scope="module")
def coulomb_not_at_rest():
    """(record, fit): the noise-free Coulomb record starting at (Z0, V0) and its fit with
    the given mass (SaDE 30 x 80, seed 1), which two tests read and neither changes."""
    rec = not_at_rest("coulomb", COULOMB)
    return rec, identify_classic(rec, "coulomb", m=COULOMB["m"], popsize=30, maxiter=80, seed=1)


def test_noise_free_coulomb_not_at_rest_recovered_to_optimiser_precision(coulomb_not_at_rest):
    """Coulomb record starting at (Z0, V0): every parameter to TOL = 1e-4 of the optimum.

    The optimum differs from the truth by the linearised offset (about 5e-4
    in k3, 1e-5 in the others; the initial-velocity stencil's error), which
    is computed and removed. A mass scaled by 1.009 inside identify moves
    every parameter by 0.9 %; a zero initial state moves them by several %.
    """
    rec, res = coulomb_not_at_rest
    lin = H.Linearisation(COULOMB, "coulomb", rec, H.FREE)
    assert_at_optimum(res, COULOMB, lin, "coulomb")
    assert res.parameters["m"] == COULOMB["m"]  # the given mass, unchanged
    # the reported J is the J of the reported parameters
    assert res.predict(rec).cost == pytest.approx(res.cost, rel=1e-6)
    assert res.nfev >= 30 * 81
    assert set(res.to_dict()["parameters"]) == {"m", "c", "k", "k3", "fc"}


def test_identified_forces_scale_exactly_with_the_given_mass(coulomb_not_at_rest):
    """Base excitation: Eq. 1 divided by m; doubling m doubles c, k, k3 and Fc, same J."""
    rec, one = coulomb_not_at_rest
    two = identify_classic(rec, "coulomb", m=2 * COULOMB["m"], popsize=30, maxiter=80, seed=1)
    for name in H.FREE:
        assert two.parameters[name] / one.parameters[name] == pytest.approx(2.0, rel=TOL), name
    assert two.cost == pytest.approx(one.cost, rel=1e-3)


def test_noisy_record_within_linearised_standard_errors():
    """Measurement noise of 1 um (0.09 % of z_rms) on a 3 s Coulomb record, skip 1 s.

    Error model (tests/_identification.py, Linearisation): noise on the
    scored samples moves ln(theta) by P eps (standard errors from the
    sensitivities: c 2.2e-4, k 1.4e-5, k3 2.0e-3, Fc 1.5e-4 relative);
    noise on the first five samples moves the initial state identify starts
    from, and its effect is computed exactly from the realised noise and
    removed, as is the noise-free offset. Each parameter is then compared at
    4 sigma, and the test is powered to see a 0.9 % error (the mis-scaled
    mass) in c, k and Fc and 2 % in k3.

    Calibration (tests/calibration/identification.py, 20 noise seeds, SaDE
    30 x 80): z-scores mean / SD / max|z|: c -0.00 / 1.09 / 1.97,
    k -0.60 / 0.78 / 2.00, k3 +0.64 / 0.86 / 2.14, Fc +0.01 / 1.09 / 2.37
    (k and k3 are strongly anti-correlated, hence their shared offset over
    only 20 seeds). With popsize 16 x 40 some seeds stop in a local minimum.
    """
    res, z, se = H.noisy_coulomb_z(noise_seed=0)
    for name, zi, sei, detect in zip(H.FREE, z, se, (0.009, 0.009, 0.02, 0.009), strict=True):
        # ln(theta_hat / theta_ref) as a statistic with its standard error
        assert_matches(
            SimpleNamespace(mean=1.0 + zi * sei, std_error=sei), 1.0, detect=detect, what=name
        )
    # J (Eq. 11) reported by identify is Eq. 11 over the scored samples
    skip = H.NOISY["skip"]
    _, noisy = H.noisy_coulomb_record(0)
    pred = predict_record(
        res.harvester(), noisy, measurement=res.measurement, skip=skip, initial_state="record"
    )
    assert res.cost == pytest.approx(pred.cost, rel=1e-9)
    # and sits at the noise floor: 100 sigma^2 / var(z) (fraction (N - d)/N of it)
    floor = 100 * H.NOISY["sigma"] ** 2 / np.var(noisy.z[skip:])
    n = noisy.n - skip
    assert abs(res.cost / floor - 1) < 4 * np.sqrt(2 / n) + 4 / n


def test_tanh_base_displacement_not_at_rest_recovered_to_optimiser_precision():
    """tanh friction (beta = 100 s/m: beta v_rms ~ 4, a smooth law, all five
    parameters identifiable), driven by a recorded base displacement that the
    package differentiates, device starting at (Z0, V0).

    The shaker fades in and out (tests/_identification.py, ``tapered``), so
    the displacement record is smooth at its ends; the record is made from
    the exact base acceleration. beta is searched in [10, 1e4] s/m: over the
    default 10 decades, a 20 x 60 search stalls in the Coulomb-like region
    (beta v_rms >> 1, J ~ 0.03). At the paper's beta (4.8e8 s/m) tanh is
    Coulomb friction and beta is not identifiable (only bounded below).
    """
    params = dict(COULOMB, beta=100.0)
    ex = H.excitation(0, 1.5, 500.0)
    y, acc = H.tapered(ex)
    device = H.harvester(params, "tanh")
    z = record_response(device, Record(ex.dt, base_acceleration=acc), substeps=8, z0=Z0, v0=V0).z[0]
    rec = Record(ex.dt, name="tanh", base_displacement=y, relative_displacement=z)
    res = identify_classic(
        rec, "tanh", m=COULOMB["m"], popsize=20, maxiter=60, seed=1, bounds={"beta": (10, 1e4)}
    )
    lin = H.Linearisation(params, "tanh", rec, H.FREE + ("beta",))
    assert_at_optimum(res, params, lin, "tanh")
    assert res.cost <= predict_record(device, rec, initial_state="record").cost


LUGRE = dict(
    m=0.0226, c=0.055, k=59.7, k3=64926.0, sigma0=1.98, sigma1=0.18, fc=0.0008, fs=0.008, vs=0.007
)  # paper Table 2, training data 1


def test_lugre_truth_scores_zero_and_the_fit_reaches_the_optimum():
    """LuGre (Table 2 values), record not at rest.

    Identifiability (linearised, 1.5 s at 1.07 m/s^2 RMS, 1 um noise): c and k
    to a few per cent; Fc, sigma0, sigma1 to tens of per cent; k3, Fs and
    the Stribeck velocity not at all (standard errors above 100 %): the
    sensitivity matrix's singular values span four decades. So the full
    8-parameter search is not tested for recovery; the truth must score
    J ~ 0 (the residual of the initial state), and with the bristle and
    Stribeck parameters held the fit must reach the optimum to TOL.
    """
    rec = not_at_rest("lugre", LUGRE)
    truth = predict_record(H.harvester(LUGRE, "lugre"), rec, initial_state="record").cost
    assert truth < 1e-6
    held = {n: LUGRE[n] for n in ("sigma0", "sigma1", "fs", "vs")}
    res = identify_classic(rec, "lugre", m=LUGRE["m"], fixed=held, popsize=16, maxiter=40, seed=1)
    assert res.free == H.FREE
    assert res.cost <= truth
    assert_at_optimum(res, LUGRE, H.Linearisation(LUGRE, "lugre", rec, H.FREE), "lugre")


def test_viscous_model_cannot_match_a_friction_record(record):
    viscous = identify_classic(record, "viscous", m=COULOMB["m"], popsize=20, maxiter=40, seed=0)
    # without friction the record cannot be matched as well (paper Fig. 7)
    assert (
        viscous.cost
        > 10 * predict_record(H.harvester(COULOMB), record, initial_state="record").cost
    )
    assert viscous.cost < 100


# the record is simulated with the linear hold, which is kept on purpose
@pytest.mark.filterwarnings("ignore:--hold linear")
def test_force_input_identifies_the_mass():
    """Force input, mass free: all five parameters to TOL of the optimum."""
    params = dict(m=0.5, c=2.0, k=800.0, k3=2e7)
    ex = band_limited_excitation(2.0, 400.0, 1.0, f_lo=2.0, f_hi=40.0, seed=2)
    force = ex["base_acceleration"]
    device = H.harvester(params, "viscous")
    z = record_response(device, Record(1 / 400, force=force), substeps=8).z[0]
    rec = Record(1 / 400, force=force, relative_displacement=z)
    res = identify_classic(rec, "viscous", popsize=30, maxiter=100, seed=0)
    assert "m" in res.free
    lin = H.Linearisation(params, "viscous", rec, ("c", "k", "k3", "m"))
    assert_at_optimum(res, params, lin, "force")
    lin = identify_classic(rec, "viscous", fixed={"k3": 0}, popsize=20, maxiter=40, seed=0)
    assert lin.parameters["k3"] == 0.0 and "k3" not in lin.free


def test_default_bounds_contain_table2_values(record):
    box = default_bounds(record, "lugre", m=TRUE["m"])
    table2_lugre = dict(
        c=0.055, k=59.7, k3=64926, sigma0=1.98, sigma1=0.18, fc=0.0008, fs=0.008, vs=0.007
    )
    for name, value in table2_lugre.items():
        lo, hi = box[name]
        assert lo < value < hi, (name, lo, hi)
    assert 4.8e8 < default_bounds(record, "tanh", m=TRUE["m"])["beta"][1]


def test_validate_scores_each_record(record):
    other = synthetic(seed=1, rms=1.5, kind="base_acceleration")
    rows = validate(H.harvester(TRUE), [record, other], initial_state="record")
    assert [r.record for r in rows] == ["test0", "test1"]
    assert all(r.cost < 1e-6 for r in rows)


def test_settings_objects_are_the_keywords(record):
    short = record.rows(0, 200)
    by_keyword = identify(
        short, "coulomb", m=TRUE["m"], popsize=8, maxiter=3, seed=4, polish=False, substeps=2,
        skip=5,
    )  # fmt: skip
    by_object = identify(
        short,
        "coulomb",
        m=TRUE["m"],
        search=SearchSettings(popsize=8, maxiter=3, seed=4, polish=False),
        simulation=SimulationSettings(substeps=2, skip=5),
    )
    assert by_object.parameters == by_keyword.parameters
    assert by_object.settings == by_keyword.settings
    # a keyword overrides the object's field
    assert identify(
        short, "coulomb", m=TRUE["m"], search=SearchSettings(popsize=8, maxiter=3, seed=4),
        polish=False, simulation=SimulationSettings(substeps=2), skip=5,
    ).parameters == by_keyword.parameters  # fmt: skip
    with pytest.raises(TypeError, match="unexpected keyword argument\\(s\\) generations"):
        identify(short, "coulomb", m=TRUE["m"], generations=3)
    with pytest.raises(
        ValueError, match="`hold` must be one of auto, linear, zero, cubic, bandlimited"
    ):
        SimulationSettings(hold="quintic")


def test_result_is_a_harvester_and_its_measurement_model(record):
    """The identified parameters as a device (c as c_m) and the measurement model; the
    result's predict is predict_record with them and the fit's settings."""
    res = identify(
        record.rows(0, 300), "coulomb", m=TRUE["m"], popsize=8, maxiter=2, seed=0, polish=False,
        substeps=2,
    )  # fmt: skip
    device, offsets = res.harvester(), res.measurement
    p = res.parameters
    assert (device.m, device.c_m, device.c_e, device.k, device.k3) == (
        p["m"], p["c"], 0.0, p["k"], p["k3"],
    )  # fmt: skip
    assert device.friction.fc == p["fc"]
    assert offsets == MeasurementModel(p["input_offset"], p["output_offset"], 0.0)
    # without the polish the fit starts from the record's first samples
    # the reconstruction as resolved for the record (auto: linear for this slow input)
    assert res.simulation == SimulationSettings(substeps=2, hold="linear", initial_state="record")
    direct = predict_record(device, record, measurement=offsets, simulation=res.simulation)
    assert res.predict(record).cost == direct.cost
    # wired: c_e of the coil added to the identified c, the load voltage simulated
    coil = rv.Resistive(0.1992, 10.0, 0.48)
    wired = res.harvester(coil)
    assert wired.c == p["c"] + coil.electrical_damping and wired.c_m == p["c"]
    assert res.predict(record, electrical=coil).voltage is not None


def test_predict_record_refuses_what_it_cannot_simulate(record):
    with pytest.raises(ValueError, match="predict_record needs a randvib.Harvester"):
        predict_record(TRUE, record)
    with pytest.raises(ValueError, match="predict_record needs scalar harvester parameters"):
        predict_record(H.harvester(dict(TRUE, fc=np.array([0.001, 0.002]))), record)
    with pytest.raises(ValueError, match="`record` must be a randvib.Record"):
        predict_record(H.harvester(TRUE), record.z)


# ------------------------------------------------------------------- CSV and CLI
def write_csv(path, record, **rename):
    frame = record.to_frame().rename(columns=rename)
    frame.to_csv(path, index=False)
    return path


def test_bad_identify_arguments(record):
    with pytest.raises(ValueError, match="`model` must be one of"):
        identify(record, "dry", m=0.02)
    with pytest.raises(ValueError, match="`m` \\(kg\\) is required"):
        identify(record, "coulomb")
    with pytest.raises(ValueError, match="`--bounds k`: lower 5.0 > upper 1.0"):
        identify(record, "coulomb", m=0.02, bounds={"k": (5, 1)})
    with pytest.raises(ValueError, match="`--fix beta`: unknown parameter for model 'coulomb'"):
        identify(record, "coulomb", m=0.02, fixed={"beta": 1.0})
    with pytest.raises(
        ValueError,
        match="has 30 samples; the lugre model with 9 free parameters needs at least 120",
    ):
        identify(record.rows(0, 30), "lugre", m=0.02)


def test_cli_identify_json_and_validate(tmp_path, capsys, record):
    data = write_csv(tmp_path / "r.csv", record.rows(0, 600))
    other = write_csv(tmp_path / "o.csv", synthetic(seed=3, duration=1.2, kind="base_acceleration"))
    params = tmp_path / "p.json"
    argv = [
        "identify", str(data), "--model", "coulomb", "--m", "0.0226", "--seed", "1",
        "--popsize", "16", "--generations", "30", "--json", "--save", str(params), "--no-polish",
    ]  # fmt: skip
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "coulomb"
    # offsets are estimated by default and reported with the parameters
    assert set(out["parameters"]) == {"m", "c", "k", "k3", "fc", "input_offset", "output_offset"}
    assert out["cost"] == pytest.approx(json.loads(params.read_text())["cost"])
    argv = ["validate", str(params), str(data), str(other), "--json", "--offsets", "given"]
    assert main(argv) == 0
    scores = json.loads(capsys.readouterr().out)
    assert [r["record"] for r in scores["records"]] == ["r", "o"]
    assert scores["records"][0]["cost"] == pytest.approx(out["cost"], rel=1e-9)
    # by default the offsets are re-estimated per record: J on the fitted record
    # is then at most the fit's (the offsets are optimised again, the rest held)
    assert main(["validate", str(params), str(data), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["records"][0]["cost"] <= out["cost"] * (1 + 1e-9)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--model", "dry", "--m", "1"], "`--model` must be one of"),
        (["--model", "coulomb"], "`--m` (kg) is required"),
        (["--model", "coulomb", "--m", "0.02", "--fix", "k3"], "`--fix` expects NAME=VALUE"),
        (
            ["--model", "coulomb", "--m", "0.02", "--bounds", "k=1"],
            "`--bounds` expects NAME=LOWER:UPPER",
        ),
        (["--model", "coulomb", "--m", "0.02", "--rows", "a:b"], "`--rows` must be START:STOP"),
    ],
)
def test_cli_errors_are_one_line(tmp_path, capsys, record, extra, message):
    data = write_csv(tmp_path / "r.csv", record.rows(0, 200))
    assert main(["identify", str(data), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_cli_missing_file(capsys):
    assert main(["identify", "nope.csv", "--model", "coulomb", "--m", "1"]) == 2
    assert "does not exist" in capsys.readouterr().err
