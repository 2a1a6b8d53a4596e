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

Run by hand (not in the default suite: 50+ mutants cost about 8 CPU-minutes)::

    python tests/mutation_check.py --record   # every mutation, its own tests; keeps
                                              # the outcomes in tests/mutation_results.txt
    python tests/mutation_check.py --list     # the table of mutations
    python tests/mutation_check.py --only noise-variance --full

``tests/test_mutations.py`` checks, in the default suite, that every mutation still
applies to exactly one place, that every kept outcome is a catch by one of its
mutation's own tests, and runs one mutant end to end.
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
from concurrent.futures import ThreadPoolExecutor
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
                "return sqdt * standard_normal(rng, j, ki, wi, fi)",
                "return 1.004987562112089 * sqdt * standard_normal(rng, j, ki, wi, fi)",
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
        tests=("tests/test_measurement_model.py::test_intervals_have_the_spread_of_the_estimates",),
        why="Standard errors left in the optimiser's scaled variables (log or per-scale) "
        "instead of the parameters' units: the 95 % intervals no longer cover the truth "
        "about 95 % of the time.",
    ),
    Mutation(
        name="output-offset-sign",
        path="randvib/identification/least_squares.py",
        edits=(
            (
                "return z[:, self.cost.skip :] + matrix[:, OUTPUT_OFFSET_COLUMN, None]",
                "return z[:, self.cost.skip :] - matrix[:, OUTPUT_OFFSET_COLUMN, None]",
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
    Mutation(
        name="tone-step-integral",
        path="randvib/montecarlo/forcing.py",
        edits=(
            (
                "gain = 2.0 * amplitude * np.sin(0.5 * omega * self.dt) / omega",
                "gain = 2.02 * amplitude * np.sin(0.5 * omega * self.dt) / omega",
            ),
        ),
        tests=("tests/test_tones.py::test_pathwise_equal_to_a_numpy_heun_on_the_same_input",),
        why="A tone's step integral 1 % too large in the kernel's forcing; the plain numpy Heun "
        "writes the integral as (A/w)(sin - sin) and must agree to rounding.",
    ),
    Mutation(
        name="forcing-strang-split",
        path="randvib/montecarlo/kernel.py",
        edits=(
            ("                    vs = vj + kick\n", "                    vs = vj + 2.0 * kick\n"),
            ("                    vn += kick\n", "                    vn += 0.0 * kick\n"),
        ),
        tests=(
            "tests/test_tones.py::test_tone_forcing_is_second_order_in_dt",
            "tests/test_tones.py::test_pathwise_equal_to_a_numpy_heun_on_the_same_input",
        ),
        why="The forcing given to the velocity all before the step (Lie splitting) instead of "
        "in two halves around it (Strang): first order in dt, which the convergence test "
        "against the exact response from rest measures.",
    ),
    Mutation(
        name="campbell-spectrum",
        path="randvib/models/shock.py",
        edits=(
            (
                "return 2.0 * self.rate * self.amplitude**2 * self.pulse_spectrum(frequency)",
                "return 2.02 * self.rate * self.amplitude**2 * self.pulse_spectrum(frequency)",
            ),
        ),
        tests=(
            "tests/test_shocks.py::"
            "test_pulse_spectrum_is_its_fourier_integral_and_campbell_integrates_to_the_variance",
        ),
        why="Campbell's spectrum of a shock train 1 % high (every linear device's analytic power "
        "under shocks with it); its integral must be lambda E[A^2] int p^2 to 1e-6.",
    ),
    Mutation(
        name="shock-step-integral",
        path="randvib/models/shock.py",
        edits=(
            (
                "return (d / np.pi) * (1.0 - np.cos(np.pi * s / d))",
                "return (d / np.pi) * 1.01 * (1.0 - np.cos(np.pi * s / d))",
            ),
        ),
        tests=("tests/test_shocks.py::test_step_integrals_of_a_pulse_are_exact",),
        why="Monte Carlo's half-sine pulse integrated 1 % too strong over each step; the steps "
        "are compared with quadrature of the pulse.",
    ),
    Mutation(
        name="harmonic-cubic-first-harmonic",
        path="randvib/analytic/harmonic_linearisation.py",
        edits=(
            (
                "k_q = k_r - 0.75 * self.k3 * motion.amplitudes**2",
                "k_q = k_r - 0.7 * self.k3 * motion.amplitudes**2",
            ),
        ),
        tests=("tests/test_tones.py::test_cubic_spring_describing_function_under_a_pure_tone",),
        why="The cubic spring's describing function under a tone with 3.05/4 instead of 3/4 "
        "k3 Z^2; the pure tone's k_q is checked against k + 3/4 k3 Z^2 to 1e-12.",
    ),
    Mutation(
        name="harmonic-friction-projection",
        path="randvib/analytic/harmonic_linearisation.py",
        edits=(
            (
                "np.where(velocity > 0, 2.0 * projections / velocity, 0.0)",
                "np.where(velocity > 0, 2.02 * projections / velocity, 0.0)",
            ),
        ),
        tests=("tests/test_tones.py::test_coulomb_describing_function_under_a_pure_tone",),
        why="A tone's friction damping 1 % too strong (its first-harmonic projection); "
        "Coulomb's describing function 4 Fc / (pi V) is checked to 0.1 %.",
    ),
    Mutation(
        name="translation-scale",
        path="randvib/models/translation.py",
        edits=(
            (
                "return np.sqrt(fit.variance) * self.marginal.g(y)",
                "return np.sqrt(1.02 * fit.variance) * self.marginal.g(y)",
            ),
        ),
        tests=(
            "tests/test_translation.py::"
            "test_synthesised_translation_has_its_variance_kurtosis_and_spectrum",
        ),
        why="The translated input's variance 2 % too large; the synthesised paths' variance is "
        "compared with the process's, powered for 2 %.",
    ),
    Mutation(
        name="line-projection",
        path="randvib/montecarlo/spectra.py",
        edits=(
            (
                "amplitude = 2.0 * (x - x.mean(axis=1, keepdims=True)) @ phasors / x.shape[1]",
                "amplitude = 2.02 * (x - x.mean(axis=1, keepdims=True)) @ phasors / x.shape[1]",
            ),
        ),
        tests=("tests/test_tones.py::test_monte_carlo_lines_are_the_tones_mean_squares",),
        why="Monte Carlo's lines 2 % high (the projection's amplitude 1 %); a tone alone on a "
        "linear device must give |H|^2 A^2 / 2 to 0.1 %.",
    ),
    Mutation(
        name="gaussian-verdict-interval",
        path="randvib/studies/gaussian_error.py",
        edits=(('size - half > tolerance, "errs"', 'size > tolerance, "errs"'),),
        tests=(
            "tests/test_study_non_gaussian.py::test_verdicts_follow_the_interval_and_the_tolerance",
        ),
        why="The study's verdict 'errs' without its interval (an error of 6 +- 2 % counted as "
        "beyond 5 %): the verdicts must follow the whole interval.",
    ),
    Mutation(
        name="assembly-tones-ignored",
        path="randvib/analytic/assembly_linear.py",
        edits=(
            ("    for tone in tones:  # superposition", "    for tone in ():  # superposition"),
        ),
        tests=(
            "tests/test_translation.py::test_assemblies_take_tones_shocks_and_translations_when_linear",
        ),
        why="A linear assembly answers under tones as if they were absent (the continuous part "
        "alone): the silent wrong answer; each line must pass through the frequency response.",
    ),
    Mutation(
        name="assembly-tone-influence",
        path="randvib/montecarlo/assembly_kernel.py",
        edits=(
            (
                "        r = 0.5 * drive[0, a]\n        for j in range(LANES):\n            keep[a, j]",
                "        r = 0.5\n        for j in range(LANES):\n            keep[a, j]",
            ),
        ),
        tests=(
            "tests/test_assembly_excitation.py::test_every_state_under_tones_equals_the_numpy_simulator[heun]",
        ),
        why="The tones' first half-kick on every DOF with unit influence, not r (the SPEC "
        "assembly's r = 0.8 on DOF 2): a tone must reach each DOF as -r a(t), like the noise.",
    ),
    Mutation(
        name="assembly-tone-amplitude",
        path="randvib/montecarlo/assembly_kernel.py",
        edits=(
            (
                "kick[j] -= g * np.cos(w * t + phase[start_path + j, q])",
                "kick[j] -= 1.1 * g * np.cos(w * t + phase[start_path + j, q])",
            ),
        ),
        tests=(
            "tests/test_assembly_excitation.py::test_linear_assembly_under_tones_matches_superposition[tones-alone-heun]",
        ),
        why="The tones' step integral 10 % large (a force 10 % too strong): a "
        "linear assembly under tones must give |h|^2 A^2 / 2 per DOF to the interval.",
    ),
    Mutation(
        name="assembly-tone-sampled-after-kick",
        path="randvib/montecarlo/assembly_kernel.py",
        edits=(
            (
                "                    if forced:\n                        _forcing_swap(ys, keep, dims)\n"
                "                    _accumulate(",
                "                    _accumulate(",
            ),
        ),
        tests=(
            "tests/test_assembly_excitation.py::test_one_dof_assembly_under_forcing_equals_the_single_mass[tones-coulomb-heun]",
        ),
        why="The window's sums read the velocities after the first half-kick (and the swap "
        "after them then puts the kicked state back wrongly): the single mass samples the "
        "state before it, and a one-DOF assembly must equal it.",
    ),
    Mutation(
        name="assembly-tones-alone-noise-on",
        path="randvib/montecarlo/assembly_setup.py",
        edits=(
            (
                "amplitude = 0.0 if silent else 1.0",
                "amplitude = 1.0 if silent else 1.0",
            ),
        ),
        tests=(
            "tests/test_assembly_excitation.py::test_linear_assembly_under_tones_matches_superposition[tones-alone-heun]",
        ),
        why="Tones alone (psd 0) with the kernel's noise left on (at the nominal level the "
        "step check sees): the assembly must see the tones alone.",
    ),
    Mutation(
        name="upcrossings-one-end",
        path="randvib/montecarlo/kernel.py",
        edits=(
            (
                "if abs(zj) <= stroke and abs(zn) > stroke:",
                "if abs(zj) <= stroke and zn > stroke:",
            ),
        ),
        tests=(
            "tests/test_reliability.py::test_paths_equal_a_numpy_heun_loop_from_the_exact_start",
        ),
        why="The kernel counts the up-crossings of +D only, not of |z| through D at both ends "
        "(half the rate); a plain numpy Heun loop on the same rows counts both.",
    ),
    Mutation(
        name="gibbs-start-velocity",
        path="randvib/montecarlo/path_simulator.py",
        edits=(
            (
                "out[:, 1] = self._gibbs.velocity_std * normals[:, 1]",
                "out[:, 1] = 1.01 * self._gibbs.velocity_std * normals[:, 1]",
            ),
        ),
        tests=(
            "tests/test_reliability.py::test_paths_equal_a_numpy_heun_loop_from_the_exact_start",
        ),
        why="The exact (Gibbs) start's velocity 1 % too spread, so the stationary start is "
        "not stationary; the numpy loop starts from the Gibbs law written out independently.",
    ),
    Mutation(
        name="subset-chain-correlation-dropped",
        path="randvib/montecarlo/subset_simulation.py",
        edits=(("    gamma = max(gamma, 0.0)\n", "    gamma = 0.0\n"),),
        tests=(
            "tests/test_reliability.py::"
            "test_chain_variance_counts_the_correlation_along_the_chains",
        ),
        why="Subset simulation's c.o.v. without Au & Beck's gamma (the chains' correlation): "
        "chains that never move hold Nc, not N, independent values, and the variance of "
        "their mean must say so exactly (the intervals' coverage, measured by "
        "tests/calibration/rare_event_coverage.py, would fall).",
    ),
    Mutation(
        name="importance-mixture-weight",
        path="randvib/montecarlo/importance_sampling.py",
        edits=(
            (
                "terms = exponent + np.log1p(np.exp(-2.0 * exponent)) - np.log(2.0)",
                "terms = exponent + np.log1p(np.exp(-2.0 * exponent)) - np.log(2.4)",
            ),
        ),
        tests=(
            "tests/test_reliability.py::"
            "test_importance_sampling_matches_the_schemes_exact_exceedance_and_rate",
        ),
        why="The mixture's density mis-normalised (each sign weighted 1/2.4): every weight "
        "20 % too large; compared with the scheme's exact exceedance and crossing rate.",
    ),
    Mutation(
        name="gibbs-crossing-rate",
        path="randvib/analytic/gibbs_marginal.py",
        edits=(
            (
                "return 2.0 * self.density(d) * self.velocity_std / np.sqrt(2.0 * np.pi)",
                "return 2.0 * self.density(d) * self.velocity_std / np.sqrt(2.1 * np.pi)",
            ),
        ),
        tests=(
            "tests/test_reliability.py::"
            "test_anchors_gibbs_and_rice_agree_on_the_linear_device_and_declare_their_cases",
        ),
        why="The exact anchor itself: Rice's rate of the Gibbs density 2.4 % low; the Gaussian "
        "route (erfc and Rice's closed form) must agree with it on a linear device to 1e-10.",
    ),
    Mutation(
        name="chain-crossing-conditional-mean",
        path="randvib/analytic/crossings.py",
        edits=(
            (
                "special.ndtr((rho * x - d) / sc)",
                "special.ndtr((0.99 * rho * x - d) / sc)",
            ),
        ),
        tests=(
            "tests/test_reliability.py::"
            "test_discrete_crossing_rate_is_the_bivariate_normal_probability_and_tends_to_rice",
        ),
        why="The reference for a scheme's discrete crossings with the one-step correlation 1 % "
        "low in one tail; checked against scipy's bivariate normal probabilities.",
    ),
    Mutation(
        name="first-passage-limit-hazard",
        path="randvib/harvester_design/constraints.py",
        edits=(
            (
                "return 1.0 - (1.0 - eps) * math.exp(-hazard * self.duration)",
                "return 1.0 - (1.0 - eps) * math.exp(-0.99 * hazard * self.duration)",
            ),
        ),
        tests=(
            "tests/test_design_first_passage.py::"
            "test_limit_is_met_on_its_boundary_by_the_analytic_search",
        ),
        why="The design's predicted P(first passage within T) with a hazard 1 % low; it must "
        "equal the crossing anchor's Vanmarcke answer for the chosen device to 1e-6.",
    ),
    Mutation(
        name="subset-runs-spread-dof",
        path="randvib/montecarlo/reliability.py",
        edits=(
            (
                "sigma2 = float(sizes @ (values - mean) ** 2) / (values.size - 1)",
                "sigma2 = float(sizes @ (values - mean) ** 2) / values.size",
            ),
        ),
        tests=("tests/test_reliability.py::test_pooled_runs_mean_and_spread_by_hand",),
        why="Subset simulation's c.o.v. from independent runs with the biased (1/R) variance: "
        "with five runs the interval 11 % too narrow; checked against the formula by hand.",
    ),
    Mutation(
        name="assembly-rare-start-covariance",
        path="randvib/montecarlo/assembly_paths.py",
        edits=(
            (
                "covariance = linalg.solve_discrete_lyapunov(a, self.dt * (b @ b.T))",
                "covariance = linalg.solve_discrete_lyapunov(a, 1.01 * self.dt * (b @ b.T))",
            ),
        ),
        tests=(
            "tests/test_reliability_assembly.py::"
            "test_linear_start_is_the_schemes_own_stationary_law",
        ),
        why="A linear assembly's exact start 1 % too spread (not the scheme's stationary law); "
        "the test solves Heun's discrete Lyapunov equation from M, C, K by hand.",
    ),
    Mutation(
        name="assembly-kernel-upcrossing-every-step",
        path="randvib/montecarlo/assembly_kernel.py",
        edits=(("    if beyond > 0.0 and was[q, j] == 0.0:\n", "    if beyond > 0.0:\n"),),
        tests=(
            "tests/test_reliability_assembly.py::"
            "test_paths_match_a_plain_numpy_heun_loop_on_the_same_rows",
        ),
        why="The assembly kernel counting every step beyond the stroke as an up-crossing; "
        "checked path by path against a plain numpy Heun loop on the same rows.",
    ),
    Mutation(
        name="assembly-kernel-linear-circuit-push",
        path="randvib/montecarlo/assembly_paths.py",
        edits=(
            (
                "f[ov : ov + n, oc + slot] -= parts.push[part] * f_s",
                "f[ov : ov + n, oc + slot] += parts.push[part] * f_s",
            ),
        ),
        tests=(
            "tests/test_reliability_assembly.py::"
            "test_linear_surrogate_is_the_kernel_on_the_same_rows",
        ),
        why="The linear system read from the kernel's tables with the coil's force reversed: "
        "the exact start and importance sampling's design points would be another device's; "
        "the surrogate must give every row the kernel's own peak.",
    ),
    Mutation(
        name="assembly-rice-rate",
        path="randvib/analytic/assembly_crossings.py",
        edits=(
            (
                "rate = float(outcrossing_rate(u2, 0.0, v2, stroke))",
                "rate = float(outcrossing_rate(u2, 0.0, 1.02 * v2, stroke))",
            ),
        ),
        tests=(
            "tests/test_reliability_assembly.py::"
            "test_rice_anchor_of_a_one_mass_assembly_is_the_single_mass_one",
        ),
        why="An assembly coordinate's exact Rice rate 1 % high; the one-mass assembly must "
        "give the single-mass Rice anchor to 1e-9.",
    ),
    Mutation(
        name="assembly-dashpot-to-ground",
        path="randvib/models/assembly.py",
        edits=(
            (
                "c += element.damping * np.outer(d, d)",
                "c += element.damping * np.diag(np.abs(d))",
            ),
        ),
        tests=(
            "tests/test_assembly_analytic.py::test_two_dof_chain_against_a_hand_built_lyapunov_equation",
        ),
        why="An element's dashpot between two DOFs acts on each DOF's absolute velocity (two "
        "dashpots to the base) instead of their relative velocity; the two-DOF chain is "
        "checked against a Lyapunov equation on a state matrix written by hand.",
    ),
    Mutation(
        name="assembly-circuit-drive",
        path="randvib/models/assembly.py",
        edits=(("a[slot, n : 2 * n] = b_s * d", "a[slot, n : 2 * n] = 1.01 * b_s * d"),),
        tests=(
            "tests/test_assembly_analytic.py::test_host_with_two_harvesters_against_a_frequency_domain_integral",
        ),
        why="A transducer's circuit state is driven 1 % too hard by its relative velocity "
        "(alpha/L or theta/C_p); the three-DOF host is checked against a frequency-domain "
        "integral with the circuits as frequency-dependent dashpots, to 1e-8.",
    ),
    Mutation(
        name="assembly-white-input-power",
        path="randvib/analytic/assembly_linear.py",
        edits=(
            (
                "return float(assembly.influence @ mr * excitation.level / 4.0)",
                "return float(assembly.influence @ mr * excitation.level / 2.0)",
            ),
        ),
        tests=("tests/test_assembly_analytic.py::test_white_noise_energy_balance_is_exact",),
        why="The injected power r^T M r S / 2 instead of / 4 (S taken as the two-sided "
        "intensity: E[w w] = (S/2) delta); the balance is written from the masses in the test.",
    ),
    Mutation(
        name="assembly-spectral-conjugate",
        path="randvib/analytic/assembly_linear.py",
        edits=(
            (
                "covariance = np.real((h * density) @ h.conj().T)",
                "covariance = np.real((h * density) @ h.T)",
            ),
        ),
        tests=(
            "tests/test_assembly_analytic.py::test_spectral_route_equals_lyapunov_for_three_dofs",
        ),
        why="The spectral covariance int Re(H H^H) S df without the conjugate: the "
        "cross-covariances (and with them the variances' real parts) are wrong; the two "
        "routes must agree to 1e-9 as correlations.",
    ),
    Mutation(
        name="assembly-cubic-closure",
        path="randvib/analytic/assembly_linearisation.py",
        edits=(
            (
                "k += 3.0 * element.spring.k3 * variance * np.outer(d, d)",
                "k += 3.3 * element.spring.k3 * variance * np.outer(d, d)",
            ),
        ),
        tests=(
            "tests/test_assembly_analytic.py::test_one_dof_assembly_equals_the_harvester",
            "tests/test_assembly_analytic.py::test_nonlinear_fixed_point_is_self_consistent",
        ),
        why="An element's Gaussian-closure spring 3.3 k3 E[u^2] instead of 3 k3 E[u^2]; the "
        "one-DOF assembly must equal the single-mass linearisation under coloured input.",
    ),
    Mutation(
        name="assembly-friction-closure",
        path="randvib/analytic/assembly_linearisation.py",
        edits=(("sigma = np.sqrt(variance)", "sigma = np.sqrt(1.02 * variance)"),),
        tests=("tests/test_assembly_analytic.py::test_one_dof_coulomb_under_white_noise_is_eq_30",),
        why="The friction's equivalent dashpot evaluated at a velocity spread 1 % too large; "
        "the one-DOF assembly under white noise must give Eq. 30 written out by hand.",
    ),
    Mutation(
        name="assembly-mc-friction-dissipation",
        path="randvib/montecarlo/assembly_results.py",
        edits=(
            (
                "total = total + self.per_path[:, self.columns.friction : self.columns.friction + e]",
                "total = total + 0.0 * self.per_path[:, self.columns.friction : self.columns.friction + e]",
            ),
        ),
        tests=("tests/test_assembly_simulation.py::test_energy_balance_of_the_nonlinear_assembly",),
        why="The assembly's Monte Carlo dissipation without the elements' friction power; "
        "the white-noise balance against r^T M r S / 4 must miss it.",
    ),
    Mutation(
        name="assembly-mc-influence-gain",
        path="randvib/montecarlo/assembly_setup.py",
        edits=(("gain[ov : ov + n] = assembly.influence", "gain[ov : ov + n] = 1.0"),),
        tests=(
            "tests/test_assembly_simulation.py::test_every_state_equals_an_independent_numpy_simulator",
        ),
        why="White noise reaching every DOF with unit weight instead of through the influence "
        "vector r; the numpy simulator's three DOFs have r = (1, 1, 0.8).",
    ),
    Mutation(
        name="assembly-kernel-coulomb-inline",
        path="randvib/montecarlo/assembly_kernel.py",
        edits=(("            fc = fp[e, 0]\n", "            fc = 1.01 * fp[e, 0]\n"),),
        tests=(
            "tests/test_assembly_simulation.py::test_every_state_equals_an_independent_numpy_simulator",
        ),
        why="The assembly kernel's written-out Coulomb law 1 % stronger than the element's "
        "F_c; the numpy simulator's Duffing harvester has Coulomb friction on DOF 1.",
    ),
    Mutation(
        name="modal-participation-transposed",
        path="randvib/models/structure.py",
        edits=(("r = phi @ gamma", "r = phi.T @ gamma"),),
        tests=("tests/test_assembly.py::test_modal_host_keeps_its_modes_and_participation",),
        why="A modal host's influence vector from the transposed mode-shape matrix; r = Phi "
        "gamma is checked with a non-symmetric Phi.",
    ),
    Mutation(
        name="assembly-budget-least-coordinate",
        path="randvib/harvester_design/assembly_budget.py",
        edits=(("worst = max(worst, float(value))", "worst = min(worst, float(value))"),),
        tests=(
            "tests/test_design_assembly.py::test_objective_counts_all_transducers_or_the_one_named",
            "tests/test_design_assembly.py::"
            "test_analytic_design_of_a_linear_two_dof_assembly_is_the_exact_optimum",
        ),
        why="An assembly's stroke budget read on its least exceeded coordinate instead of its "
        "worst: the design ignores the budget; the optimum must keep sigma_u within it by a "
        "hand-built Lyapunov equation, and the reported exceedance be the largest.",
    ),
    Mutation(
        name="assembly-objective-first-transducer",
        path="randvib/harvester_design/objectives.py",
        edits=(
            (
                "return range(len(assembly.transducers))",
                "return range(min(1, len(assembly.transducers)))",
            ),
        ),
        tests=(
            "tests/test_design_assembly.py::test_objective_counts_all_transducers_or_the_one_named",
        ),
        why="The objective of all transducers counts only the first: checked against the sum "
        "of the prediction's per-transducer load powers.",
    ),
    Mutation(
        name="single-mass-answer-damping",
        path="randvib/studies/assembly_cases.py",
        edits=(("mechanical_block(m, c_m + c_e, k)", "mechanical_block(m, c_e, k)"),),
        tests=(
            "tests/test_study_assemblies.py::"
            "test_single_mass_answer_under_white_noise_is_the_kanai_tajimi_answer",
        ),
        why="The study's single-mass answer loses the harvester's mechanical damping; under "
        "white base noise it must equal the single-mass harvester's exact power under the "
        "host's Kanai-Tajimi spectrum.",
    ),
    Mutation(
        name="paired-verdict-ignores-interval",
        path="randvib/studies/assembly_cases.py",
        edits=(("    if mean - ci95 > 0:\n", "    if mean > 0:\n"),),
        tests=("tests/test_study_assemblies.py::test_array_verdicts_from_a_constructed_table",),
        why="The assemblies study calls an array better when its paired difference is merely "
        "positive, not significantly so; the constructed table has a positive difference "
        "inside its interval.",
    ),
    Mutation(
        name="unmeasured-check-counted",
        path="randvib/studies/assembly_cases.py",
        edits=(
            (
                "for r in checks.itertuples() if _measured(r.power_mc, r.power_mc_ci95)]",
                "for r in checks.itertuples()]",
            ),
        ),
        tests=(
            "tests/test_study_assemblies.py::test_single_mass_verdicts_from_a_constructed_table",
        ),
        why="The assemblies study counts a check without a Monte Carlo run (NaN, no assembly "
        "kernel) as a Monte Carlo check; the constructed table has one such row.",
    ),
    Mutation(
        name="two-mass-linearisation-verdict-reversed",
        path="randvib/studies/assembly_cases.py",
        edits=(
            (
                '{"above": "two-mass", "below": "single mass", "equal": "neither"}',
                '{"above": "single mass", "below": "two-mass", "equal": "neither"}',
            ),
        ),
        tests=("tests/test_study_assemblies.py::test_two_mass_verdicts_from_a_constructed_table",),
        why="The assemblies study's verdict without Monte Carlo names the device linearisation "
        "predicts the lesser power; the constructed table has one case each way.",
    ),
    Mutation(
        name="analytic-tie-ignored",
        path="randvib/studies/assembly_cases.py",
        edits=(('return "below" if gain < -ANALYTIC_TIE else "equal"', 'return "below"'),),
        tests=("tests/test_study_assemblies.py::test_array_verdicts_from_a_constructed_table",),
        why="The assemblies study calls an array worse than one harvester when their exact "
        "optima differ only by the searches' rounding (2e-9 in the constructed table; (b)'s "
        "arrays converge to N equal harvesters).",
    ),
    Mutation(
        name="ljung-box-dof",
        path="randvib/identification/residuals.py",
        edits=(
            ("return q, float(stats.chi2.sf(q, m))", "return q, float(stats.chi2.sf(q, m - 1))"),
        ),
        tests=(
            "tests/test_residuals.py::test_ljung_box_is_its_definition",
            "tests/test_residuals.py::test_false_alarm_rates_of_white_residuals_hold_their_levels",
        ),
        why="The Ljung-Box p-value from chi-squared with M - 1 degrees of freedom instead of "
        "M (at M = 25 its false alarms rise from 1 % to 1.4 %): Q and its p-value against "
        "the definition computed in the test; over 1000 white residuals (M = 10) 60 % of "
        "p-values fall below 0.5 instead of 50 %.",
    ),
    Mutation(
        name="ljung-box-n-plus-2",
        path="randvib/identification/residuals.py",
        edits=(("q = float(n * (n + 2) * np.sum(", "q = float(n * n * np.sum("),),
        tests=("tests/test_residuals.py::test_ljung_box_is_its_definition",),
        why="Ljung-Box's N (N + 2) becomes N^2, Q too small by N / (N + 2) (1 % at N = 200): "
        "against the definition computed in the test.",
    ),
    Mutation(
        name="ljung-box-n-minus-k",
        path="randvib/identification/residuals.py",
        edits=(("r**2 / (n - np.arange(1, m + 1))", "r**2 / (n - np.arange(0, m))"),),
        tests=("tests/test_residuals.py::test_ljung_box_is_its_definition",),
        why="Lag k of Ljung-Box's sum weighted by 1 / (N - k + 1) instead of 1 / (N - k): "
        "against the definition computed in the test.",
    ),
    Mutation(
        name="ljung-box-lag-cap",
        path="randvib/identification/residuals.py",
        edits=(
            (
                "    m = int(min(max_lag, n // 4))\n    if m < 1 or np.std(e) == 0:",
                "    m = int(min(max_lag, n // 2))\n    if m < 1 or np.std(e) == 0:",
            ),
        ),
        tests=("tests/test_residuals.py::test_ljung_box_is_its_definition",),
        why="ljung_box caps M at N / 2 instead of the documented N / 4, so a short residual "
        "is tested over lags its autocorrelation cannot estimate; the 60-sample case of the "
        "definition test sees M = 25 instead of 15.",
    ),
    Mutation(
        name="cross-band-constant",
        path="randvib/identification/residuals.py",
        edits=(("z = stats.norm.ppf(1 - LEVEL / 2)", "z = stats.norm.ppf(1 - LEVEL)"),),
        tests=("tests/test_residuals.py::test_bands_and_p_values_are_their_definitions",),
        why="The bands' quantile one-sided (2.33 instead of 2.58): the reported 99 % bands "
        "of the auto- and cross-correlation are 98 % bands; against the definitions.",
    ),
    Mutation(
        name="bartlett-factor",
        path="randvib/identification/residuals.py",
        edits=(
            (
                "float(1 + 2 * np.sum(r_ee[1:] * r_uu[1:]))",
                "float(1 + np.sum(r_ee[1:] * r_uu[1:]))",
            ),
        ),
        tests=(
            "tests/test_residuals.py::test_bands_and_p_values_are_their_definitions",
            "tests/test_residuals.py::test_cross_correlation_band_holds_its_level_for_coloured_series",
        ),
        why="Bartlett's variance of the cross-correlation counts the lags on one side only "
        "(1 + sum instead of 1 + 2 sum): the band is too narrow for a coloured residual and "
        "input, 4.4 % of independent AR(1) pairs outside it at lag 0 instead of 1 %.",
    ),
    Mutation(
        name="cross-p-one-sided",
        path="randvib/identification/residuals.py",
        edits=(("p_cross = 2 * stats.norm.sf(", "p_cross = stats.norm.sf("),),
        tests=("tests/test_residuals.py::test_bands_and_p_values_are_their_definitions",),
        why="The cross-correlation lags' p-values one-sided, half the two-sided ones: the "
        "input test rejects twice as often; against Holm's adjusted p-value computed in the "
        "test.",
    ),
    Mutation(
        name="cross-p-without-holm",
        path="randvib/identification/residuals.py",
        edits=(
            (
                "cross_p = float(min(1.0, p_cross.size * np.min(p_cross)))",
                "cross_p = float(min(1.0, np.min(p_cross)))",
            ),
        ),
        tests=(
            "tests/test_residuals.py::test_bands_and_p_values_are_their_definitions",
            "tests/test_residuals.py::test_false_alarm_rates_of_white_residuals_hold_their_levels",
        ),
        why="The reported cross-correlation p-value is the smallest lag's, not Holm's "
        "adjusted one over the 2M + 1 lags: 40 % of independent white pairs would read as "
        "related at 1 % (M = 25; 19 % at the white-residual test's M = 10).",
    ),
    Mutation(
        name="verdict-without-holm",
        path="randvib/identification/residuals.py",
        edits=(
            (
                "related = bool(np.any(holm_significant(p_cross, LEVEL)))",
                "related = bool(np.any(p_cross <= LEVEL))",
            ),
        ),
        tests=(
            "tests/test_residuals.py::test_false_alarm_rates_of_white_residuals_hold_their_levels",
        ),
        why="The verdict's input test rejects when any of the 2M + 1 lags does at LEVEL, "
        "without Holm's correction: about 40 % of white residuals of independent inputs are "
        "'structured' at M = 25, 20 % at the test's M = 10 (nominal at most 2 %).",
    ),
    Mutation(
        name="verdict-ljung-box-level",
        path="randvib/identification/residuals.py",
        edits=(
            (
                'verdict = "white" if q_p >= LEVEL and not related',
                'verdict = "white" if q_p >= LEVEL / 10 and not related',
            ),
        ),
        tests=(
            "tests/test_residuals.py::test_false_alarm_rates_of_white_residuals_hold_their_levels",
        ),
        why="The verdict reads the Ljung-Box p-value at LEVEL / 10: residuals with "
        "0.001 <= p < 0.01 pass as white; the white-residual test checks the verdict's rule on "
        "each of its 1000 pairs (about 9 fall there).",
    ),
    Mutation(
        name="holm-bonferroni",
        path="randvib/statistics.py",
        edits=(("if p[i] > level / (p.size - rank):", "if p[i] > level / p.size:"),),
        tests=("tests/test_statistics.py::test_holm_is_the_rule_of_adjusted_p_values",),
        why="Holm's step-down becomes Bonferroni (level / m at every step, not level / (m - "
        "i)): fewer rejections after the first; compared with Holm's adjusted p-values.",
    ),
    Mutation(
        name="holm-no-step-down",
        path="randvib/statistics.py",
        edits=(
            (
                "            break\n        reject[i] = True",
                "            continue\n        reject[i] = True",
            ),
        ),
        tests=("tests/test_statistics.py::test_holm_is_the_rule_of_adjusted_p_values",),
        why="Holm's procedure does not stop at its first acceptance: a larger p-value that "
        "meets its own threshold level / (m - i) is rejected after a smaller one was not; "
        "compared with Holm's adjusted p-values.",
    ),
    Mutation(
        name="circuit-force-in-record-kernel",
        path="randvib/identification/record_integrator.py",
        edits=(
            (
                "return e - dev[1] * v - z * (dev[2] + z * (dev[5] + z * dev[3])) - dev[9] * x",
                "return e - dev[1] * v - z * (dev[2] + z * (dev[5] + z * dev[3])) - 1.01 * dev[9] * x",
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_piezo_circuit_state_matches_an_independent_rk4_to_fourth_order",
        ),
        why="The record simulation's circuit pushes the mass 1 % too hard (theta V or alpha i): "
        "the piezo's voltage is compared with plain RK4 of the device and its circuit to 5e-8.",
    ),
    Mutation(
        name="coil-load-voltage",
        path="randvib/identification/circuit.py",
        edits=(
            (
                'scale = r_load if kind == "voltage" else 1.0  # the coil\'s voltage is R_L i',
                'scale = 1.01 * r_load if kind == "voltage" else 1.0',
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_coil_with_inductance_and_coulomb_friction_matches_the_generator",
        ),
        why="A coil's load voltage read 1 % high (R_L i): compared with the independent "
        "generator's R_L i to 1.5e-4 of its RMS.",
    ),
    Mutation(
        name="nonlinear-forces-not-per-mass",
        path="randvib/identification/identifiability.py",
        edits=(
            (
                'parts.append(np.atleast_1d(p[name] / p["m"] if force_like else p[name]))',
                "parts.append(np.atleast_1d(p[name]))",
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_what_records_can_fix_agrees_with_the_symmetries_worked_out_by_hand",
        ),
        why="The structural test takes the nonlinear forces (k3, Fc) as seen by themselves "
        "instead of per unit mass: under base excitation the mass would look fixed by a "
        "displacement record, against Eq. 1 divided by m.",
    ),
    Mutation(
        name="blocked-covariance-pooled",
        path="randvib/identification/least_squares.py",
        edits=(
            (
                "middle += float(eb @ eb) / dof * (jb.T @ jb)",
                "middle += float(e @ e) / max(n - d, 1) * (jb.T @ jb)",
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_blocked_covariance_gives_each_channel_its_own_noise",
        ),
        why="The channels' noise pooled into one variance: a quiet channel's parameters "
        "get the noisy channel's standard errors (a factor of about 25 in variance).",
    ),
    Mutation(
        name="profiled-start-sign",
        path="randvib/identification/experiment.py",
        edits=(
            (
                'total = total + np.einsum("ij,ij->i", shift, cross)',
                'total = total - np.einsum("ij,ij->i", shift, cross)',
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_the_unmeasured_start_is_profiled_out_of_the_search_cost",
        ),
        why="The search's J with the unmeasured start profiled out adds the least-squares "
        "gain instead of taking it off: J at the truth is no longer the noise's.",
    ),
    Mutation(
        name="channel-weight-ignored",
        path="randvib/identification/experiment.py",
        edits=(
            (
                "norm[kind] = 100.0 * weight / ((y.size - skip) * variance)",
                "norm[kind] = 100.0 / ((y.size - skip) * variance)",
            ),
        ),
        tests=(
            "tests/test_electrical_identification.py::"
            "test_weights_multiply_each_channels_own_j_in_the_sum",
        ),
        why="`--weight KIND=W` is dropped from the summed J: the weighted cost is compared "
        "with w times the channel's own J, exactly.",
    ),
    Mutation(
        name="assembly-record-drive-scale",
        path="randvib/identification/assembly_record.py",
        edits=(
            (
                "source = RecordedInput(acceleration, substeps,",
                "source = RecordedInput(1.01 * acceleration, substeps,",
            ),
        ),
        tests=(
            "tests/test_assembly_record.py::test_one_dof_assembly_matches_the_single_mass_record",
        ),
        why="`record --device` drives the assembly with a base acceleration 1 % too large "
        "(the input column stays right); the one-DOF record is compared path for path with the "
        "single mass's within the schemes' step error, about 0.1 % of the signal.",
    ),
    Mutation(
        name="assembly-record-circuit-row",
        path="randvib/identification/assembly_record.py",
        edits=(
            (
                "state[:, oc + order.circuits.index(index)]",
                "state[:, oc + order.circuits.index(index) - 1]",
            ),
        ),
        tests=(
            "tests/test_assembly_record.py::test_one_dof_assembly_matches_the_single_mass_record",
        ),
        why="A transducer's voltage and current read the kernel row before its circuit "
        "state (off by one); the one-DOF record's coil voltage and current are compared with "
        "the single mass's.",
    ),
    Mutation(
        name="assembly-record-velocity-dof",
        path="randvib/identification/assembly_record.py",
        edits=(
            (
                'true[record_column("relative_velocity", i)] = v[:, i]',
                'true[record_column("relative_velocity", i)] = v[:, -1 - i]',
            ),
        ),
        tests=(
            "tests/test_assembly_record.py::"
            "test_linear_two_dof_mean_squares_match_the_exact_variances",
        ),
        why="The velocity columns name the wrong DOFs (reversed); each column's mean square "
        "is compared with its own DOF's exact variance.",
    ),
    Mutation(
        name="bridge-record-one-diode-drop",
        path="randvib/montecarlo/rectified_kernel.py",
        edits=(
            (
                "over = abs(e) - v_out - 2.0 * v_d",
                "over = abs(e) - v_out - v_d",
            ),
        ),
        tests=(
            "tests/test_record_bridge.py::"
            "test_bridge_record_matches_an_independent_rk4_within_its_step_error",
        ),
        why="The coil's bridge counts one diode's drop instead of the two conducting ones; "
        "the record simulation behind a bridge (which steps this function) is compared "
        "pathwise with an independent RK4 of the bridge's equations.",
    ),
    Mutation(
        name="bridge-inductive-reverse-current",
        path="randvib/montecarlo/rectified_kernel.py",
        edits=(
            (
                "        if rkind == 3 and s1n * s1 < 0.0:  # the diodes block the reverse current\n"
                "            s1n = 0.0",
                "        if rkind == 3 and s1n * s1 < 0.0:  # the diodes block the reverse current\n"
                "            s1n = s1n",
            ),
        ),
        tests=(
            "tests/test_record_bridge.py::"
            "test_bridge_record_matches_an_independent_rk4_within_its_step_error",
        ),
        why="The coil's current with inductance is let through the diodes in reverse at the "
        "step's end (the predictor still blocks it); the record simulation behind the bridge "
        "is compared pathwise with an independent RK4 that blocks it.",
    ),
    Mutation(
        name="bridge-record-input-integral",
        path="randvib/identification/record_bridge.py",
        edits=(
            (
                "hh * (seg[1] - u_off + hh * (0.5 * seg[2] + hh * seg[3] / 3.0))",
                "hh * (seg[1] - u_off + hh * (seg[2] + hh * seg[3] / 3.0))",
            ),
        ),
        tests=(
            "tests/test_record_bridge.py::"
            "test_bridge_record_matches_an_independent_rk4_within_its_step_error",
        ),
        why="The recorded input's integral over a sub-step doubles its linear term (an "
        "O(h^2) error per sub-step): the record simulation behind a bridge falls to first "
        "order, which the pathwise comparison's measured order (> 3 from 4 to 8 sub-steps) "
        "rejects.",
    ),
    Mutation(
        name="fitted-bridge-ideal-diodes",
        path="randvib/identification/circuit.py",
        edits=(
            (
                "values.update({k: float(v) for k, v in bridge.items()})",
                'values.update({k: float(v) for k, v in bridge.items() if k != "v_diode"})',
            ),
        ),
        tests=(
            "tests/test_bridge_fit.py::"
            "test_a_bridged_fit_saves_its_bridge_and_validate_scores_through_it",
        ),
        why="A saved fit's bridge is rebuilt without its diodes' drop (ideal diodes): "
        "validate on the training record, through the file's bridge, must score the fit's "
        "own J to 1e-6.",
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
    # one process per mutant (the caller runs mutants side by side; --full spreads the
    # whole suite over the cores), in the named tests' own order
    workers = ["-n", "auto"] if full else ["-n", "0"]
    cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *workers]
    cmd += ["-p", "no:randomly", *targets]
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


#: The last full run's outcome per mutation (``python tests/mutation_check.py --record``),
#: read by tests/test_mutations.py: the default suite does not run 50+ mutants (each
#: a pytest process and often a numba recompile: about 8 CPU-minutes in all).
RESULTS = ROOT / "tests" / "mutation_results.txt"


def _git_state() -> str:
    """The commit the mutants were made from, ``+dirty`` when the tree had edits."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=ROOT,
            capture_output=True,
            text=True,
        ).stdout.strip()
    except OSError:
        return "unknown"
    return (head or "unknown") + ("+dirty" if dirty else "")


def _first_failure(outcome: Outcome) -> str:
    """The node id of the first failed test in a mutant's run ('-' if none)."""
    for line in outcome.output.splitlines():
        if line.startswith("FAILED "):
            return line.split()[1]
    return "-"


def write_results(outcomes: list, path: Path = RESULTS) -> None:
    """Keep a run's outcomes: one line per mutation (name, verdict, seconds, first failure)."""
    lines = [
        "# python tests/mutation_check.py --record: the curated mutants and what caught them",
        f"# commit {_git_state()}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
        f"python {sys.version.split()[0]}",
    ]
    for o in outcomes:
        verdict = "caught" if o.caught else ("NOT-CAUGHT" if o.returncode == 0 else "ERROR")
        lines.append(f"{o.mutation.name}\t{verdict}\t{o.seconds:.0f}\t{_first_failure(o)}")
    path.write_text("\n".join(lines) + "\n")


def read_results(path: Path = RESULTS) -> dict[str, tuple[str, str]]:
    """{mutation name: (verdict, first failed test)} from :data:`RESULTS`."""
    results = {}
    for line in path.read_text().splitlines():
        if line and not line.startswith("#"):
            name, verdict, _seconds, failed = line.split("\t")
            results[name] = (verdict, failed)
    return results


def run_all(chosen, full: bool = False, jobs: int = 2) -> list:
    """Every chosen mutant, ``jobs`` at a time; outcomes in the order of ``chosen``.

    A mutant's run is mostly one pytest process (and numba recompiling what the
    mutation reaches) on one core, so runs side by side fill the machine.
    """
    with tempfile.TemporaryDirectory(prefix="mutants-") as tmp:

        def run(mutation, project):
            outcome = run_prepared(mutation, project, full=full)
            print(outcome.summary(), flush=True)
            return outcome

        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            futures = []
            for mutation in chosen:  # prepared here, one at a time: ast.parse of CPython
                work = Path(tmp) / mutation.name  # 3.11 is not re-entrant; runs start at once
                work.mkdir()
                futures.append(pool.submit(run, mutation, prepare_mutant(mutation, work)))
            return [future.result() for future in futures]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", metavar="NAME", help="mutations to run")
    parser.add_argument("--full", action="store_true", help="run the whole suite per mutant")
    parser.add_argument("--list", action="store_true", help="print the mutations and exit")
    parser.add_argument(
        "--markdown", action="store_true", help="print the table for docs/testing.md and exit"
    )
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="mutants run side by side"
    )
    parser.add_argument(
        "--record", action="store_true", help=f"keep the outcomes in {RESULTS.relative_to(ROOT)}"
    )
    args = parser.parse_args(argv)
    unknown = sorted(set(args.only or ()) - {m.name for m in MUTATIONS})
    if unknown:
        parser.error(f"--only: no mutation named {', '.join(unknown)} (see --list)")
    chosen = [m for m in MUTATIONS if not args.only or m.name in args.only]
    if args.markdown:
        print(markdown_table(chosen), end="")
        return 0
    if args.list:
        for m in chosen:
            print(f"{m.name:28s} {m.path:32s} {', '.join(m.tests)}\n    {m.why}")
        return 0
    if args.record and (args.only or args.full):
        parser.error("--record keeps a run of every mutation on its own tests: drop --only/--full")
    outcomes = run_all(chosen, full=args.full, jobs=args.jobs)
    survivors = sum(not o.caught for o in outcomes)
    print(f"{len(chosen) - survivors} of {len(chosen)} mutations caught")
    if args.record:
        write_results(outcomes)
    return 1 if survivors else 0


if __name__ == "__main__":
    sys.exit(main())
