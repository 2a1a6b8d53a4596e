"""Mutation check: would the test suite notice a wrong number?

Each entry of :data:`MUTATIONS` is a small *semantic* error of the kind that
passes every type check and most smoke tests (a variance 1 % too large, a mass
0.9 % off, a forgotten initial state, a weight in a scheme changed). The check
copies the project into a scratch folder, applies one mutation there, runs the
tests named in the entry (the ones documented to catch it) and requires that
they **fail** (pytest exit status 1: tests ran and failed, not a collection or
import error). A mutation the suite lets through is a hole in the suite.

The named tests are the documentation of which test catches which mutation;
``python tests/mutation_check.py --full`` runs the whole suite against each
mutant instead, to find every test that notices it.

The project's own tree is never modified. numba's on-disk cache is copied for
the modules the mutation cannot reach (numba keys a cached kernel on its own
bytecode only, not on the functions it calls from other modules, so every
module that imports the mutated one, directly or not, is recompiled).

Run by hand::

    python tests/mutation_check.py            # every mutation, its own tests
    python tests/mutation_check.py --list     # the table of mutations
    python tests/mutation_check.py --only noise-variance --full

and in the test suite by ``tests/test_mutations.py`` (marked ``slow``).
"""

from __future__ import annotations

import argparse
import ast
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "randvib"
# docs/ and examples/: tests/test_docs.py builds the site from them (``--full``)
COPIED = ("randvib", "tests", "studies", "docs", "examples", "pyproject.toml", "README.md", ".ci")
NUMBA_CACHE_SUFFIXES = (".nbi", ".nbc")


@dataclass(frozen=True)
class Mutation:
    """One deliberate error and the tests that must catch it.

    Attributes
    ----------
    name : str
        Short identifier (used by ``--only`` and as the pytest id).
    path : str
        File to mutate, relative to the project root.
    edits : tuple of (str, str)
        ``(original, mutated)`` source fragments; each ``original`` must occur
        exactly once in the file, so that the list cannot rot silently.
    tests : tuple of str
        pytest node ids that must fail on the mutant.
    why : str
        What the mutation models and why these tests see it.
    """

    name: str
    path: str
    edits: tuple[tuple[str, str], ...]
    tests: tuple[str, ...]
    why: str


MUTATIONS: tuple[Mutation, ...] = (
    Mutation(
        name="noise-variance",
        path="randvib/montecarlo/kernel.py",
        edits=(
            (
                "dwj = sqdt * standard_normal(rng, j, ki, wi, fi)",
                "dwj = 1.004987562112089 * sqdt * standard_normal(rng, j, ki, wi, fi)",
            ),
        ),
        tests=("tests/test_simulation.py::test_linear_oscillator_continuous_time_variances",),
        why="The engine's Brownian increments have 1 % too much variance, so every "
        "stationary variance is 1 % too large; the exact-variance tests are powered for 1 %.",
    ),
    Mutation(
        name="filter-damping-in-kernel",
        path="randvib/montecarlo/kernel.py",
        edits=(("r2 = a21 * x1 + a22 * x2", "r2 = a21 * x1 + 1.05 * a22 * x2"),),
        tests=("tests/test_simulation_coloured.py::test_coarse_step_exact",),
        why="The shaping filter's damping term is 5 % too large in the first stage of the "
        "filter-state step (the whole of Euler-Maruyama's, half of Heun's), so the base "
        "acceleration's spectrum is wrong; the coarse-step tests compare with the scheme's "
        "exact recursion on device + filter.",
    ),
    Mutation(
        name="control-variate-mean",
        path="randvib/statistics.py",
        edits=(
            (
                "residual[test] = y[test] - x[test] @ coef[1:]",
                "residual[test] = 1.01 * (y[test] - x[test] @ coef[1:])",
            ),
        ),
        tests=("tests/test_simulation.py::test_duffing_without_friction_matches_gibbs_density",),
        why="The controlled estimator is scaled by 1.01; a controlled estimate is "
        "compared with an exact, independent variance (not with the friction-free "
        "companion, which equals the device at Fc = 0 whatever the engine does).",
    ),
    Mutation(
        name="coulomb-force-in-kernel",
        path="randvib/models/friction.py",
        edits=(
            ("        return p[0], 0.0\n", "        return 1.01 * p[0], 0.0\n"),
            ("        return -p[0], 0.0\n", "        return -1.01 * p[0], 0.0\n"),
        ),
        tests=("tests/test_simulation.py::test_energy_balance_identity_with_coulomb_and_duffing",),
        why="The compiled Coulomb force is 1 % too strong in the kernels; the energy balance "
        "c E[v^2] + Fc E|v| = S m/4 uses the declared Fc, not the kernel's force.",
    ),
    Mutation(
        name="linearisation-constant",
        path="randvib/models/friction.py",
        edits=(
            (
                "a = 4.0 * fc**2 / (np.pi * psd * m)",
                "a = 4.04 * fc**2 / (np.pi * psd * m)",
            ),
        ),
        tests=("tests/test_linearisation.py",),
        why="Eq. 30's 4 Fc^2/(pi S m) term 1 % too large; checked against Eq. 30 by hand "
        "and against the general Eq. 19-20 fixed point.",
    ),
    Mutation(
        name="heun-corrector-weight",
        path="randvib/montecarlo/integrators.py",
        edits=(
            (
                'HEUN = Integrator("heun", 1.0, 2.0, "stratonovich", (0.5, 0.5))',
                'HEUN = Integrator("heun", 1.0, 2.0, "stratonovich", (0.51, 0.49))',
            ),
        ),
        tests=("tests/test_simulation.py::test_pathwise_equal_to_sdeint",),
        why="The trapezoidal corrector weights 0.51/0.49 instead of 1/2; the pathwise "
        "comparison with sdeint.stratHeun on the same increments sees it.",
    ),
    Mutation(
        name="tanh-force-in-kernel",
        path="randvib/models/friction.py",
        edits=(
            (
                "return p[0] * np.tanh(p[1] * v), 0.0",
                "return 1.01 * p[0] * np.tanh(p[1] * v), 0.0",
            ),
        ),
        tests=("tests/test_friction.py",),
        why="The compiled tanh force 1 % too strong; the kernel is compared with the "
        "numpy force law.",
    ),
    Mutation(
        name="lugre-damping-in-kernel",
        path="randvib/models/friction.py",
        edits=(
            (
                "return p[0] * theta + p[1] * rate, rate",
                "return p[0] * theta + 1.01 * p[1] * rate, rate",
            ),
        ),
        tests=("tests/test_friction.py",),
        why="LuGre's bristle damping sigma1 1 % too large in the kernels.",
    ),
    Mutation(
        name="gibbs-reference",
        path="randvib/analytic/exact_solutions.py",
        edits=(("0.25 * eps * x**4", "0.2525 * eps * x**4"),),
        tests=("tests/test_fokker_planck.py",),
        why="The exact Gibbs density's quartic term 1 % too strong: the reference that "
        "Monte Carlo, FPK and averaging are checked against must itself be checked.",
    ),
    Mutation(
        name="eq11-cost-normalisation",
        path="randvib/identification/cost.py",
        edits=(
            (
                "return 100.0 * sse / (self.n_scored * self.variance)",
                "return 101.0 * sse / (self.n_scored * self.variance)",
            ),
        ),
        tests=("tests/test_identification.py::test_search_cost_is_eq11_of_predict_record",),
        why="The compiled-batch cost used by the search is 1 % off Eq. 11 (the reported J is "
        "recomputed, so only the search's own cost and its history show it).",
    ),
    Mutation(
        name="fpk-richardson-weight",
        path="randvib/analytic/fokker_planck.py",
        edits=(
            (
                "out[(row,) + index] = (4.0 * a_f - a_c) / 3.0",
                "out[(row,) + index] = (4.04 * a_f - a_c) / 3.0",
            ),
        ),
        tests=("tests/test_fokker_planck.py",),
        why="The FPK solver's Richardson extrapolation mis-weighted (about 1.3 % on every moment).",
    ),
    Mutation(
        name="load-power-share",
        path="randvib/models/coupling.py",
        edits=(
            (
                "return self.r_load / (self.r_load + self.r_coil)",
                "return 1.01 * self.r_load / (self.r_load + self.r_coil)",
            ),
        ),
        tests=("tests/test_harvester.py::test_expected_load_power_is_i_squared_r_load",),
        why="The share of electrical power reaching the load 1 % too large; the expected "
        "load power is checked against i^2 R_L written out by hand.",
    ),
    Mutation(
        name="identification-mass",
        path="randvib/identification/identify.py",
        edits=(
            (
                "        fixed=fixed,\n",
                '        fixed={k: v * 1.009 if k == "m" else v for k, v in fixed.items()},\n',
            ),
        ),
        tests=(
            "tests/test_identification.py::test_noise_free_coulomb_not_at_rest_recovered_to_optimiser_precision",
        ),
        why="identify silently simulates with the user's mass x 1.009: every force parameter "
        "comes back 0.9 % off at J ~ 0; parameters are checked to 1e-4 of the optimum.",
    ),
    Mutation(
        name="initial-velocity-zeroed",
        path="randvib/identification/cost.py",
        edits=(
            (
                "self.v0 = float(initial_velocity(record.z, record.dt))",
                "self.v0 = 0.0",
            ),
        ),
        tests=(
            "tests/test_identification.py::test_true_parameters_score_the_residual_of_the_initial_state",
        ),
        why="The record simulation starts at rest instead of at the record's estimated "
        "velocity; the test records do not start at rest.",
    ),
    Mutation(
        name="initial-displacement-zeroed",
        path="randvib/identification/cost.py",
        edits=(("self.z0 = float(record.z[0] - offset)", "self.z0 = float(0.0 - offset)"),),
        tests=(
            "tests/test_identification.py::test_true_parameters_score_the_residual_of_the_initial_state",
        ),
        why="The record simulation starts at z = 0 instead of the first sample.",
    ),
    Mutation(
        name="cost-counts-skipped-samples",
        path="randvib/identification/cost.py",
        edits=(("self.n_scored = scored.size", "self.n_scored = record.n"),),
        tests=(
            "tests/test_identification.py::test_noisy_record_within_linearised_standard_errors",
        ),
        why="Eq. 11's N counts the skipped transient samples too; the noisy-record test "
        "compares identify's J with predict's J on a record with skipped samples.",
    ),
    Mutation(
        name="holm-family-level",
        path="randvib/studies/contrasts.py",
        edits=(
            (
                'table["detectable_holm"] = holm_significant(table.p_value, level)',
                'table["detectable_holm"] = holm_significant(table.p_value, 2 * level)',
            ),
        ),
        tests=("tests/test_studies.py::test_interaction_contrasts_holm_at_family_level",),
        why="The studies' Holm correction runs at twice the family level (10 % for 5 %), "
        "so contrasts that pass only on their own count as detectable after correction; "
        "the test's z-scores pass at 10 % and not at 5 %.",
    ),
    Mutation(
        name="band-pass-psd-constant",
        path="randvib/models/excitation.py",
        edits=(
            (
                "return self.level * (2.0 * self.zeta * f * self.f0) ** 2 / self._denominator(f)",
                "return 1.01 * self.level * (2.0 * self.zeta * f * self.f0) ** 2 / self._denominator(f)",
            ),
        ),
        tests=("tests/test_excitation_models.py::test_psd_is_the_shaping_filters_gain",),
        why="The band-pass PSD formula 1 % high; it is compared with |H|^2 S of its shaping "
        "filter to 1e-12.",
    ),
    Mutation(
        name="lyapunov-noise-intensity",
        path="randvib/models/excitation.py",
        edits=(("return 0.5 * self.noise_psd", "return self.noise_psd"),),
        tests=(
            "tests/test_linear_response.py::test_white_noise_variances_of_the_linear_oscillator",
        ),
        why="The Lyapunov equation driven with intensity S instead of S/2 (E[w w] = (S/2) "
        "delta): every variance doubles; the white-noise case is checked against S m/(4c).",
    ),
    Mutation(
        name="k-eq-factor",
        path="randvib/analytic/statistical_linearisation.py",
        edits=(
            (
                "k_eq = k + 3.0 * k3 * var_z",
                "k_eq = k + 3.3 * k3 * var_z",
            ),
        ),
        tests=("tests/test_linear_response.py::test_white_noise_reduces_to_eq30_32",),
        why="k_eq = k + 3.3 k3 E[z^2] instead of 3 k3 E[z^2]; under white noise the "
        "displacement variance must equal Eq. 20's with the Gaussian-closure spring.",
    ),
    Mutation(
        name="stroke-tail-cut",
        path="randvib/analytic/fokker_planck.py",
        edits=(
            (
                "return float(integral(stroke, z_far) / integral(0.0, z_far))",
                "return float(integral(1.01 * stroke, z_far) / integral(0.0, z_far))",
            ),
        ),
        tests=(
            "tests/test_potentials.py::test_fpk_solvers_match_the_gibbs_density_of_any_confining_potential",
        ),
        why="fpk-fast's stroke exceedance integrates from 1 % beyond the stroke, so every "
        "tail probability comes out low; checked against the exact Gibbs exceedance of "
        "double wells and the pure cubic to 1e-4.",
    ),
    Mutation(
        name="synthesis-amplitude",
        path="randvib/models/excitation.py",
        edits=(("scale = np.full(size, 0.5 * n)", "scale = np.full(size, 0.505 * n)"),),
        tests=("tests/test_excitation_models.py::test_synthesised_band_limited_variance_and_psd",),
        why="Synthesised paths 1 % too large in amplitude (2 % in variance); the variance "
        "test is powered for 2 % (standard error 0.25 %).",
    ),
    Mutation(
        name="circuit-drive-in-kernel",
        path="randvib/montecarlo/kernel_setup.py",
        edits=(
            (
                "a[n_filter, n_filter], b[n_filter], c[n_filter] = a_x, b_x, f / h.m",
                "a[n_filter, n_filter], b[n_filter], c[n_filter] = a_x, 1.01 * b_x, f / h.m",
            ),
        ),
        tests=(
            "tests/test_coupling.py::test_coarse_step_exact_with_circuit_state"
            "[heun-white-inductive]",
        ),
        why="The kernel's circuit state is driven 1 % too hard by the velocity (alpha/L "
        "or theta/C_p), so E[i^2] is about 2 % too large; the coarse-step test compares "
        "with the scheme's exact recursion on device + circuit, powered for 1 %.",
    ),
    Mutation(
        name="synthesis-step-integral",
        path="randvib/models/excitation.py",
        edits=(
            (
                "step = np.where(omega > 0, np.expm1(1j * omega * dt) / (1j * omega), dt)",
                "step = np.where(omega > 0, dt * np.exp(1j * omega * dt), dt)",
            ),
        ),
        tests=(
            "tests/test_simulation_synthesised.py::"
            "test_increments_are_exact_step_integrals_of_the_synthesised_sum",
        ),
        why="Monte Carlo's synthesised input as the end-of-step sample times dt instead of "
        "the exact step integral (1.6 % too much power at 20 Hz, a phase shift of half a "
        "step); the increments must equal the closed-form integrals to rounding.",
    ),
    Mutation(
        name="resume-trusts-stored-rows",
        path="randvib/montecarlo/sweep.py",
        edits=(
            (
                'if _row_checksum(row) != stored.get("row_sha256"):',
                'if _row_checksum(row) == "trusted":',
            ),
        ),
        tests=("tests/test_resume.py::test_corrupted_point_is_named_and_recomputed",),
        why="A resumed sweep trusts each stored row without its checksum, so a stored power "
        "changed on disk (doubled) flows into the table and the verdicts; the test doubles "
        "one and requires it to be recomputed.",
    ),
    Mutation(
        name="devices-equal-input",
        path="randvib/studies/grids.py",
        edits=(
            (
                "level = shape.level * psd * device.m / (4 * device.c) / linear",
                "level = shape.level * psd * device.m / (4 * device.c_m) / linear",
            ),
        ),
        tests=("tests/test_study_devices.py::test_equal_input_power_and_the_bistable_choice",),
        why="The band-pass level of the devices study (grids.response_matched) matched with "
        "the mechanical damping c_m instead of c = c_m + c_e: the band injects twice the "
        "white-noise power into the "
        "linear device, so the white/band comparison is not at equal input power; the "
        "injected power c E[v^2] must be g S m / 4 to 1e-9 (exact Lyapunov solution).",
    ),
    Mutation(
        name="covariance-chain-rule-dropped",
        path="randvib/identification/least_squares.py",
        edits=(
            (
                "cov = cov_u * np.outer(dtheta_du, dtheta_du)",
                "cov = cov_u",
            ),
        ),
        tests=("tests/test_measurement_model.py::test_95_percent_intervals_cover_the_truth",),
        why="Standard errors left in the optimiser's scaled variables (log or per-scale) "
        "instead of the parameters' units: the 95 % intervals no longer cover the truth "
        "about 95 % of the time.",
    ),
    Mutation(
        name="output-offset-sign",
        path="randvib/identification/least_squares.py",
        edits=(
            (
                "return z[:, self.cost.skip :] + matrix[:, -1:]",
                "return z[:, self.cost.skip :] - matrix[:, -1:]",
            ),
        ),
        tests=("tests/test_measurement_model.py::test_sensor_offsets_do_not_change_the_estimate",),
        why="The output sensor's offset subtracted instead of added (measured = true + "
        "offset): the fit is unchanged but the reported offset has the wrong sign.",
    ),
    Mutation(
        name="power-mechanical-includes-electrical",
        path="randvib/cli/power.py",
        edits=(
            (
                'out["power_mechanical"] = (result.c_eq - harvester.c_e) * result.velocity_variance',
                'out["power_mechanical"] = result.c_eq * result.velocity_variance',
            ),
        ),
        tests=("tests/test_cli_conventions.py::test_power_mechanical_closes_the_energy_balance",),
        why="`randvib power`'s mechanical dissipation counts the electrical power too: "
        "mechanical + electrical must equal the injected m S / 4 to 1e-12 under white noise "
        "(energy balance, c_eq = S m / (4 E[v^2])).",
    ),
    Mutation(
        name="event-noise-gain",
        path="randvib/montecarlo/kernel.py",
        edits=(("noise = noise * gain", "noise = noise * gain * 1.05"),),
        tests=("tests/test_transient_simulation.py::test_monte_carlo_matches_the_exact_transient",),
        why="An event's white noise is 5 % too strong in the kernel (10 % too much injected "
        "variance); the ensemble's energy is compared with the Lyapunov solution, the "
        "scheme's exact bias removed, powered for 6 %.",
    ),
    Mutation(
        name="event-filter-coupling",
        path="randvib/analytic/transient.py",
        edits=(
            (
                "a[self.iv, : self.n_filter] = e * self._coupling",
                "a[self.iv, : self.n_filter] = e * e * self._coupling",
            ),
        ),
        tests=(
            "tests/test_transient_analytic.py::"
            "test_enveloped_filtered_noise_against_the_evolutionary_spectrum",
        ),
        why="The transient Lyapunov equation applies the envelope's square to a filtered "
        "input's coupling (a step hides it); Priestley's evolutionary spectrum of the "
        "modulated process, an independent route, sees it.",
    ),
    Mutation(
        name="caughey-stumpf-phase",
        path="randvib/analytic/exact_solutions.py",
        edits=(
            (
                "(1.0 - decay * (1.0 + r * sin2 + 2 * r * r * square))",
                "(1.0 - decay * (1.0 - r * sin2 + 2 * r * r * square))",
            ),
        ),
        tests=(
            "tests/test_transient_analytic.py::"
            "test_caughey_stumpf_closed_form_against_its_own_derivative_and_integral",
        ),
        why="The reference itself: Caughey and Stumpf's E[z^2] with the phase term's sign "
        "flipped; its derivative must be twice the closed-form E[z z'].",
    ),
    Mutation(
        name="wilson-centre",
        path="randvib/statistics.py",
        edits=(
            (
                "centre = (p + z2n / 2.0) / (1.0 + z2n)",
                "centre = (p + z2n / 2.0) / (1.0 + 1.1 * z2n)",
            ),
        ),
        tests=("tests/test_statistics.py::test_wilson_interval_is_the_score_test_inverted",),
        why="A probability's Wilson interval (the stroke reached, the time beyond it) with its "
        "centre pulled towards zero: the ends are no longer where the score test gives z.",
    ),
    Mutation(
        name="causal-anticausal-share",
        path="randvib/analytic/harvesting_limit.py",
        edits=(("share = m * m / (16.0 * c_m)", "share = m * m / (8.0 * c_m)"),),
        tests=(
            "tests/test_harvesting_bounds.py::"
            "test_causal_limit_is_the_riccati_optimum_as_its_penalty_vanishes",
        ),
        why="The causal bound removes twice the anti-causal share m^2 L(p)^2 p / (16 c_m): "
        "it falls below what the linear-quadratic (Riccati) optimum of device and shaping "
        "filter, solved independently, actually takes.",
    ),
    Mutation(
        name="record-bound-primal-residual",
        path="randvib/analytic/harvesting_limit.py",
        edits=(
            (
                "return min(dual, squares) * stroke**2, squares * stroke**2, fit.status > 0",
                "return squares * stroke**2, squares * stroke**2, fit.status > 0",
            ),
        ),
        tests=(
            "tests/test_harvesting_bounds.py::"
            "test_record_limit_is_certified_when_its_solver_stops_short",
        ),
        why="The record bound trusts the least-squares solver's point instead of its dual "
        "certificate: a solver stopped at its iteration limit gives a 'bound' below the "
        "converged one.",
    ),
    Mutation(
        name="record-bound-at-rest",
        path="randvib/analytic/harvesting_limit.py",
        edits=(("/ (4.0 * c_m) + kinetic / duration", "/ (4.0 * c_m) + 0.0 * kinetic / duration"),),
        tests=(
            "tests/test_harvesting_bounds.py::"
            "test_record_limit_counts_the_kinetic_energy_a_device_starts_with",
        ),
        why="The record bound forgets the kinetic energy a device starts with: a device "
        "moving when the record starts (independent DOP853 run) takes more than it.",
    ),
    Mutation(
        name="bridge-idle-threshold",
        path="randvib/models/rectifier.py",
        edits=(
            (
                "threshold = self.threshold(v_out)\n",
                "threshold = self.threshold(v_out) - self.v_diode\n",
            ),
        ),
        tests=(
            "tests/test_bridge_idle.py::"
            "test_advice_names_the_rms_the_threshold_and_what_would_help",
        ),
        why="An idle bridge's explanation counts one diode drop instead of two (a half-wave "
        "rectifier's threshold): the threshold it quotes, V_b + 2 V_d = 4.3 V for the issue's "
        "device, and its ratio to the EMF's exact RMS are wrong.",
    ),
    Mutation(
        name="rice-bound-half",
        path="randvib/analytic/first_passage.py",
        edits=(
            (
                "np.minimum(1.0, start_beyond + _cumulative(times, rate))",
                "np.minimum(1.0, start_beyond + 0.5 * _cumulative(times, rate))",
            ),
        ),
        tests=(
            "tests/test_first_passage_bound.py::"
            "test_crossing_bound_integrates_a_stationary_rate_exactly",
        ),
        why="Rice's bound on P(stroke reached) counts half the expected out-crossings (one "
        "side of the barrier): no longer an upper bound; checked against the stationary "
        "rate's exact integral.",
    ),
)


# ---------------------------------------------------------------------------
# Copying and mutating
# ---------------------------------------------------------------------------


def _module_name(path: Path, root: Path) -> str:
    rel = path.relative_to(root).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imported_modules(path: Path, module: str, known: set[str]) -> set[str]:
    """Package modules imported anywhere in ``path`` (function-level imports included)."""
    tree = ast.parse(path.read_text())
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base_parts = package.split(".")
                base_parts = base_parts[: len(base_parts) - (node.level - 1)]
                base = ".".join(base_parts + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            names = [base] + [f"{base}.{alias.name}" for alias in node.names]
        else:
            continue
        for name in names:
            # "randvib.montecarlo.kernel.run_ensemble" imports randvib.montecarlo.kernel (and randvib)
            while name:
                if name in known:
                    found.add(name)
                name = name.rpartition(".")[0]
    return found


def reaching_modules(root: Path, mutated_file: str) -> set[str]:
    """Modules that are, or import directly or transitively, the mutated module."""
    files = {_module_name(p, root): p for p in (root / PACKAGE).rglob("*.py")}
    known = set(files)
    imports = {name: _imported_modules(path, name, known) for name, path in files.items()}
    target = _module_name(root / mutated_file, root)
    reached = {target}
    changed = True
    while changed:
        changed = False
        for name, deps in imports.items():
            if name not in reached and deps & reached:
                reached.add(name)
                changed = True
    return reached


def copy_project(dest: Path, source: Path = ROOT) -> None:
    """Copy the files the tests need; numba caches come along, other caches do not."""

    def ignore(directory, names):
        skip = {".hypothesis", ".pytest_cache", ".benchmarks", "calibration_output"}
        skip |= {"_build", "generated", "auto_examples", "sg_execution_times.rst"}  # docs output
        return [n for n in names if n in skip or n.endswith(".pyc")]

    for name in COPIED:
        src = source / name
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=ignore, copy_function=shutil.copy2)
        elif src.exists():
            shutil.copy2(src, dest / name)


def drop_stale_numba_caches(root: Path, mutation: Mutation) -> list[Path]:
    """Delete cached kernels of every module the mutation reaches (see module docstring)."""
    removed = []
    for module in reaching_modules(root, mutation.path):
        parts = module.split(".")
        path = root.joinpath(*parts)
        if path.is_dir():  # a package: its __init__'s kernels, if any
            cache_dir, stem = path / "__pycache__", "__init__"
        else:
            cache_dir, stem = path.parent / "__pycache__", parts[-1]
        if not cache_dir.is_dir():
            continue
        for cached in cache_dir.iterdir():
            if cached.name.startswith(stem + ".") and cached.suffix in NUMBA_CACHE_SUFFIXES:
                cached.unlink()
                removed.append(cached)
    return removed


def apply(mutation: Mutation, root: Path) -> None:
    """Apply the edits in place under ``root``; each original must occur exactly once."""
    path = root / mutation.path
    text = path.read_text()
    for original, mutated in mutation.edits:
        count = text.count(original)
        if count != 1:
            raise ValueError(
                f"mutation {mutation.name!r}: {original!r} occurs {count} times in "
                f"{mutation.path} (must be exactly once); update the mutation list"
            )
        text = text.replace(original, mutated)
    path.write_text(text)


# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------


@dataclass
class Outcome:
    mutation: Mutation
    returncode: int
    output: str
    seconds: float

    @property
    def caught(self) -> bool:
        # 1: tests were collected and at least one failed. 2 (interrupted, e.g. a
        # collection error), 4 (usage, unknown node id) or 5 (nothing collected)
        # mean the harness, not the suite, spoke.
        return self.returncode == 1

    def summary(self) -> str:
        verdict = "caught" if self.caught else "NOT CAUGHT"
        if self.returncode not in (0, 1):
            verdict = f"harness error (pytest exit {self.returncode})"
        tail = [line for line in self.output.splitlines() if line.startswith("FAILED")]
        shown = "; ".join(tail[:3]) if tail else self.output.strip().splitlines()[-1:]
        return f"{self.mutation.name}: {verdict} in {self.seconds:.0f} s ({shown})"


def prepare_mutant(mutation: Mutation, workdir: Path) -> Path:
    """Copy the project under ``workdir`` and mutate the copy; returns its root.

    Not thread-safe (``ast.parse`` of CPython 3.11 is not re-entrant across
    threads): prepare mutants one at a time, then run them concurrently.
    """
    root = workdir / "project"
    copy_project(root)
    apply(mutation, root)
    drop_stale_numba_caches(root, mutation)
    return root


def run_prepared(
    mutation: Mutation, root: Path, full: bool = False, timeout: float = 900
) -> Outcome:
    """Run the mutation's tests (or the whole suite) in a prepared mutant copy."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTEST_ADDOPTS")}
    env["MPLBACKEND"] = "Agg"
    # the mutant must be what the tests import (python -m puts the cwd first on sys.path)
    where = subprocess.run(
        [sys.executable, "-c", f"import {PACKAGE}; print({PACKAGE}.__file__)"],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    if not Path(where).resolve().is_relative_to(root.resolve()):
        raise RuntimeError(f"the mutant copy is not the imported package ({where})")
    targets = ["tests"] if full else list(mutation.tests)
    cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *targets]
    cmd += ["--ignore", "tests/test_mutations.py"]  # no mutants of mutants
    start = time.perf_counter()
    proc = subprocess.run(
        cmd, cwd=root, env=env, capture_output=True, text=True, timeout=timeout, check=False
    )
    return Outcome(
        mutation, proc.returncode, proc.stdout + proc.stderr, time.perf_counter() - start
    )


def run_mutant(
    mutation: Mutation, workdir: Path, full: bool = False, timeout: float = 900
) -> Outcome:
    """Copy the project under ``workdir``, mutate it and run the mutation's tests."""
    return run_prepared(mutation, prepare_mutant(mutation, workdir), full=full, timeout=timeout)


def markdown_table(mutations=MUTATIONS) -> str:
    """The mutation table of docs/testing.md (pipes in the texts escaped)."""

    def cell(text):
        return text.replace("|", "\\|")

    rows = ["| mutation | file | what it models | caught by |", "|---|---|---|---|"]
    for m in mutations:
        tests = ", ".join(f"`{t.rpartition('::')[2] or t}`" for t in m.tests)
        rows.append(f"| `{m.name}` | `{m.path}` | {cell(m.why)} | {cell(tests)} |")
    return "\n".join(rows) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", metavar="NAME", help="mutations to run")
    parser.add_argument("--full", action="store_true", help="run the whole suite per mutant")
    parser.add_argument("--list", action="store_true", help="print the mutations and exit")
    parser.add_argument(
        "--markdown", action="store_true", help="print the table for docs/testing.md and exit"
    )
    args = parser.parse_args(argv)
    chosen = [m for m in MUTATIONS if not args.only or m.name in args.only]
    if args.markdown:
        print(markdown_table(chosen), end="")
        return 0
    if args.list:
        for m in chosen:
            print(f"{m.name:28s} {m.path:32s} {', '.join(m.tests)}\n    {m.why}")
        return 0
    survivors = 0
    for mutation in chosen:
        with tempfile.TemporaryDirectory(prefix=f"mutant-{mutation.name}-") as tmp:
            outcome = run_mutant(mutation, Path(tmp), full=args.full)
        print(outcome.summary(), flush=True)
        survivors += not outcome.caught
    print(f"{len(chosen) - survivors} of {len(chosen)} mutations caught")
    return 1 if survivors else 0


if __name__ == "__main__":
    sys.exit(main())
