"""Paired ensembles (randvib/montecarlo/ensembles.py): seeds by group, paired estimates, resume.

Every case must be exactly what :func:`randvib.simulate` gives with its
group's seed and its start (the studies' tables depend on it bit for bit);
cases of one group share their paths, groups do not; the paired ratio and
contrast are the combinations of the cases' own estimates; a run written to
a folder resumes without recomputing, names and recomputes a corrupted case,
and refuses a folder of another run.
"""

import json

import numpy as np
import pytest

import randvib as rv
import randvib.montecarlo.ensembles as ensembles_module
from randvib.montecarlo.ensembles import GROUP_SEEDS

BASE = rv.preset("figure9").updated(fc=0.0058, stroke=0.006)
SETTINGS = rv.SweepSettings(dt=2e-4, window=1.0, burn_in=0.25, min_paths=24, max_paths=24,
                            batch_paths=24, seed=3, control_variates=False)  # fmt: skip
BAND = rv.BandPass(2.0, 8.0, 0.2)


def _cases():
    """Two springs under white noise (group "w", stationary start), the same two under a band
    from rest (group "b"), and a lone case (its own group)."""
    cases = [rv.Case({"input": "white", "k3": k3}, BASE.updated(k3=k3), 1.0, group="w")
             for k3 in (0.0, 5e5)]  # fmt: skip
    cases += [rv.Case({"input": "band", "k3": k3}, BASE.updated(k3=k3), BAND, group="b",
                      initial="rest") for k3 in (0.0, 5e5)]  # fmt: skip
    return cases + [rv.Case({"input": "lone", "k3": 0.0}, BASE.updated(k3=0.0), 1.0)]


@pytest.fixture(scope="module")
def run():
    return rv.run_ensembles(_cases(), SETTINGS, workers=1, progress=False)


def test_each_case_is_simulate_on_its_groups_seed(run):
    assert run.groups == [0, 0, 1, 1, 2]
    for i, case in enumerate(run.cases):
        direct = rv.simulate(case.device, case.excitation, t_end=1.25, dt=2e-4, n_paths=24,
                             burn_in=0.25, seed=GROUP_SEEDS * 3 + run.groups[i],
                             initial=case.initial, progress=False)  # fmt: skip
        assert np.array_equal(run.per_path[i], direct.per_path)
        row = run.table.iloc[i]
        assert row.power_electrical == direct.power_electrical.mean
        assert row.stroke_exceedance_ci95 == direct.stroke_exceedance.ci95
        first = direct.stroke_first_passage
        assert row.first_passage_reached == first.paths_reached
        assert row.first_passage_restricted_mean == first.restricted_mean.mean
    assert list(run.table.columns[:2]) == ["input", "k3"]
    # the same device in another group: other paths; on its group's seed: the same paths
    assert not np.array_equal(run.per_path[0], run.per_path[4])
    lone = rv.run_ensembles(
        [rv.Case({"input": "white", "k3": 0.0}, BASE.updated(k3=0.0), 1.0, group="w")],
        SETTINGS,
        workers=1,
        progress=False,
    )
    assert np.array_equal(lone.per_path[0], run.per_path[0])


def test_paired_ratio_and_contrast_are_the_cases_combinations(run):
    ratios = run.paired_ratios(k3=0.0)
    assert ratios.ratio[0] == 1.0 and ratios.ratio_ci95[0] == pytest.approx(0.0, abs=1e-15)
    power = run.table.power_electrical
    assert ratios.ratio[3] == pytest.approx(power[3] / power[2], rel=1e-12)
    contrast = run.paired({3: 1.0, 2: -1.0})
    assert contrast.mean == pytest.approx(power[3] - power[2], rel=1e-9)
    unpaired = np.hypot(run.table.power_electrical_ci95[3], run.table.power_electrical_ci95[2])
    assert contrast.ci95 < unpaired  # common paths: the noise largely cancels
    assert run.partner(3, k3=0.0) == 2 and run.find(1, k3=5e5) == 3
    with pytest.raises(ValueError, match="only cases of one group share their paths"):
        run.paired({0: 1.0, 2: -1.0})
    with pytest.raises(ValueError, match="0 cases of group 1 have the labels"):
        run.paired_ratios(input="white")


def test_with_control_variates_a_case_is_its_simulation_and_paired_uses_its_controls():
    """With the run's control variates, :meth:`simulation` is :func:`randvib.simulate`'s result
    (statistics and controls), and the paired contrast regresses on both cases' controls,
    exactly as the same estimate formed from the two direct runs."""
    from randvib.statistics import estimate

    settings = rv.SweepSettings(dt=2e-4, window=1.0, burn_in=0.25, min_paths=48, max_paths=48,
                                batch_paths=48, seed=3, control_variates=True)  # fmt: skip
    cases = [rv.Case({"k3": k3}, BASE.updated(k3=k3, stroke=None), 1.0, group="w")
             for k3 in (0.0, 5e5)]  # fmt: skip
    run = rv.run_ensembles(cases, settings, workers=1, progress=False)
    direct = [rv.simulate(c.device, 1.0, t_end=1.25, dt=2e-4, n_paths=48, burn_in=0.25,
                          seed=GROUP_SEEDS * 3, companion=True, control_variates=True,
                          progress=False) for c in cases]  # fmt: skip
    for i, d in enumerate(direct):
        rebuilt = run.simulation(i)
        assert rebuilt.power_electrical == d.power_electrical
        assert np.array_equal(rebuilt.controls(), d.controls())
    power = [d.harvester.c_e * d.averages.v2 for d in direct]
    expected = estimate(
        power[1] - power[0], np.hstack([direct[1].controls(), direct[0].controls()])
    )
    assert run.paired({1: 1.0, 0: -1.0}) == expected
    plain = estimate(power[1] - power[0])
    assert expected.ci95 < plain.ci95  # the controls absorb most of the paired noise


def test_a_run_resumes_names_a_corrupted_case_and_refuses_another(tmp_path, monkeypatch):
    cases = _cases()[:2]
    first = rv.run_ensembles(cases, SETTINGS, out_dir=tmp_path, workers=1, progress=False)
    calls = []
    real = ensembles_module.run_case

    def counting(case, settings, seed, threads=1):
        calls.append(dict(case.labels))
        return real(case, settings, seed, threads)

    monkeypatch.setattr(ensembles_module, "run_case", counting)
    again = rv.run_ensembles(cases, SETTINGS, out_dir=tmp_path, workers=1, progress=False)
    assert calls == []
    columns = [c for c in first.table.columns if c != "wall_time"]
    assert again.table[columns].equals(first.table[columns])
    stored = tmp_path / "points" / "00001.json"
    record = json.loads(stored.read_text())
    record["row"]["power_electrical"] *= 2
    stored.write_text(json.dumps(record))
    with pytest.warns(UserWarning, match="case 1 .* unusable"):
        again = rv.run_ensembles(cases, SETTINGS, out_dir=tmp_path, workers=1, progress=False)
    assert calls == [{"input": "white", "k3": 5e5}]
    assert again.table[columns].equals(first.table[columns])
    with pytest.raises(FileExistsError, match="different run"):
        rv.run_ensembles(cases[:1], SETTINGS, out_dir=tmp_path, workers=1, progress=False)


def test_worker_processes_give_the_same_cases(run):
    pooled = rv.run_ensembles(_cases()[:3], SETTINGS, workers=2, progress=False)
    for i in range(3):
        assert np.array_equal(pooled.per_path[i], run.per_path[i])


def test_bad_cases_are_refused_by_name():
    case = rv.Case({"input": "white"}, BASE, 1.0)
    with pytest.raises(ValueError, match="labels"):
        rv.run_ensembles([case, rv.Case({"level": 1.0}, BASE, 1.0)], SETTINGS, progress=False)
    with pytest.raises(ValueError, match="two cases have the labels"):
        rv.run_ensembles([case, case], SETTINGS, progress=False)
    with pytest.raises(ValueError, match="non-empty list of randvib Case"):
        rv.run_ensembles([], SETTINGS, progress=False)
    with pytest.raises(ValueError, match="`labels` must map names"):
        rv.Case({"input": [1]}, BASE, 1.0)
    with pytest.raises(ValueError, match="psd"):
        rv.Case({"input": "white"}, BASE, -1.0)
    many = [rv.Case({"i": i}, BASE, 1.0) for i in range(GROUP_SEEDS + 1)]
    with pytest.raises(ValueError, match=f"at most {GROUP_SEEDS} groups"):
        rv.run_ensembles(many, SETTINGS, progress=False)
