"""The design's end-stop constraint P(|z| reaches the stroke within T) <= P.

Covers :mod:`randvib.harvester_design.constraints` (``FirstPassageLimit``), its
use in :mod:`randvib.harvester_design.search` and :mod:`randvib.harvester_design.design`,
and ``randvib design --max-first-passage P --duration T`` (:mod:`randvib.cli.design`).
The prediction is checked against the closed form from Rice's rate and
Vanmarcke's hazard of the exact Lyapunov solution; the confirmation against the
rare-event estimate of :func:`randvib.first_passage` run independently.
"""

import json
import math

import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.analytic.crossings import CROSSING_METHODS
from randvib.harvester_design.constraints import FirstPassageLimit
from randvib.harvester_design.search import InfeasibleBudget
from randvib.montecarlo.sweep import SweepSettings

M, C_M = 0.0226, 0.049
BAND = rv.BandPass(1.0, 8.0, 0.1)
VARY = {"c_e": (0.01, 1)}


def fixed():
    return rv.Harvester(m=M, c_m=C_M, c_e=0.1, k=57.4, stroke=0.003)


def test_limit_is_met_on_its_boundary_by_the_analytic_search():
    """Linear device, band-pass input: the predicted P_T = 1 - (1 - eps) exp(-h T) is the
    crossing anchor's Vanmarcke answer for the chosen device (rice: exact Lyapunov
    variances, Rice's rate, Vanmarcke's hazard: an independent route); asking for half
    the unconstrained optimum's P_T makes the limit active, and SLSQP ends on it."""
    duration = 10.0
    free = rv.design(fixed(), BAND, VARY, monte_carlo=False)
    free_p = FirstPassageLimit(0.5, duration).predicted(_candidate(free))
    bound = 0.5 * free_p
    result = rv.design(fixed(), BAND, VARY, monte_carlo=False, max_first_passage=bound,
                       duration=duration)  # fmt: skip
    anchor = CROSSING_METHODS["rice"].solve(result.device, BAND, 0.003, duration)
    assert result.first_passage_probability_predicted == pytest.approx(
        anchor.first_passage_vanmarcke, rel=1e-6
    )
    assert result.first_passage_probability_predicted == pytest.approx(bound, rel=1e-6)
    assert result.power_predicted < free.power_predicted
    assert result.to_dict()["max_first_passage"] == bound
    with pytest.raises(InfeasibleBudget, match="first-passage constraint P"):
        rv.design(fixed(), BAND, VARY, monte_carlo=False, max_first_passage=1e-300,
                  duration=duration)  # fmt: skip


def _candidate(result):
    """The optimum as the search's candidate (its predicted exceedance and E[tau])."""
    from types import SimpleNamespace

    return SimpleNamespace(exceedance=result.exceedance_predicted,
                           first_passage=result.first_passage_predicted)  # fmt: skip


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(max_first_passage=0.1), "go together"),
        (dict(duration=1.0), "go together"),
        (dict(max_first_passage=1.5, duration=1.0), "`max_first_passage` must be in"),
        (dict(max_first_passage=0.1, duration=-1.0), "`duration` must be"),
    ],
)
def test_limit_arguments_are_checked(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        rv.design(fixed(), BAND, VARY, monte_carlo=False, **kwargs)


def test_monte_carlo_candidates_are_confirmed_by_the_rare_event_estimate():
    """White noise, a linear device, c_e varied: the chosen candidate's probability is the
    subset-simulation estimate of first_passage on it (the same seed reproduces it), and
    a loose limit is confirmed (its 95 % interval lies below it)."""
    settings = SweepSettings(dt=1e-3, window=0.5, burn_in=0.2, min_paths=32, max_paths=32,
                             seed=4, control_variates=True)  # fmt: skip
    device = rv.Harvester(m=M, c_m=C_M, c_e=0.1, k=57.4, stroke=0.006)
    result = rv.design(device, 1.0, {"c_e": (0.05, 0.5)}, exceedance=0.01, settings=settings,
                       workers=1, runners_up=1, max_first_passage=0.3, duration=0.2)  # fmt: skip
    assert result.first_passage_probability_confirmed is True
    p = result.first_passage_probability
    again = rv.first_passage(result.device, 1.0, duration=0.2, target_cov=0.2, seed=4,
                             progress=False).probability_first_passage  # fmt: skip
    assert p.mean == again.mean and p.mean + p.ci95 <= 0.3
    anchor = CROSSING_METHODS["rice"].solve(result.device, 1.0, 0.006, 0.2)
    lo, hi = anchor.first_passage_bounds
    assert lo < p.mean + 2 * p.ci95 and p.mean - 2 * p.ci95 < hi
    assert json.loads(json.dumps(result.to_dict()))["first_passage_probability"]["mean"] == p.mean


def test_cli_design_max_first_passage(capsys):
    base = ["design", "--m", M, "--c-m", C_M, "--excitation", "band-pass", "--psd", 1,
            "--f0", 8, "--zeta", 0.1, "--stroke", 0.003, "--k", 57.4, "--c-e", 0.1,
            "--vary", "c_e=0.01:1", "--no-monte-carlo"]  # fmt: skip
    code, out, _ = run(capsys, *base, "--max-first-passage", 0.5, "--duration", 10, "--json")
    assert code == 0
    data = json.loads(out)
    api = rv.design(fixed(), BAND, VARY, monte_carlo=False, max_first_passage=0.5, duration=10.0)
    assert data["first_passage_probability_predicted"] == pytest.approx(
        api.first_passage_probability_predicted
    )
    assert math.isfinite(data["first_passage_probability_predicted"])
    one_line_error(capsys, [*base, "--max-first-passage", 0.5], "go together")
