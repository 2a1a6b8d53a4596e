"""randvib: random-vibration analysis of nonlinear energy harvesters with friction.

Implements and extends Green, Worden & Sims, "On the identification and
modelling of friction in a randomly excited energy harvester". SI units
throughout; S is the one-sided PSD of the base acceleration in (m/s^2)^2/Hz.
"""

# Public names load on first use (PEP 562): ``import randvib`` stays light, and
# a script that only simulates never pays for the identification, FPK or
# plotting stacks (time and memory; see benchmarks/bench_engine.py).
import importlib as _importlib

__version__ = "0.1.0"

#: Submodule -> public names it provides, re-exported here.
_EXPORTS = {
    "randvib.analytic.averaging": (
        "averaging_statistics",
        "AveragingValidityWarning",
        "energy_density",
        "orbit_averages",
    ),
    "randvib.identification.record_response": ("BatchSimulation", "record_response"),
    "randvib.models.excitation": (
        "as_excitation",
        "band_limited_excitation",
        "BandLimited",
        "BandPass",
        "Excitation",
        "EXCITATIONS",
        "KanaiTajimi",
        "Measured",
        "Tabulated",
        "White",
    ),
    "randvib.models.tone": ("Tone",),
    "randvib.models.shock": ("ShockTrain",),
    "randvib.models.translation": ("Marginal", "Translated"),
    "randvib.models.combined": ("Combined",),
    "randvib.analytic.harmonic_linearisation": (
        "combined_linearisation",
        "CombinedLinearisation",
        "ToneResponse",
    ),
    "randvib.analytic.statistical_linearisation": (
        "LinearisationResult",
        "LinearisationValidityWarning",
        "statistical_linearisation",
    ),
    "randvib.analytic.linear_response": ("ResponseSpectra",),
    "randvib.models.event": (
        "Boxcar",
        "Enveloped",
        "Envelope",
        "ENVELOPES",
        "EventStart",
        "ShinozukaSato",
        "Step",
        "TabulatedEnvelope",
    ),
    "randvib.analytic.transient": ("transient_response", "TransientPrediction"),
    "randvib.analytic.fokker_planck": ("fast_fpk_statistics", "fpk_statistics", "solve_fpk"),
    "randvib.models.friction": ("Coulomb", "FrictionModel", "LuGre", "Tanh"),
    "randvib.models.harvester": ("Harvester",),
    "randvib.models.assembly": ("Assembly",),
    "randvib.models.assembly_parts": ("Element", "ElectricalDamper", "Spring", "Transducer"),
    "randvib.models.coupling": ("Coupling", "COUPLINGS", "Inductive", "Piezo", "Resistive"),
    "randvib.models.rectifier": ("BridgeCoil", "BridgePiezo", "RECTIFIED", "Rectified"),
    "randvib.identification.cost": ("normalised_cost",),
    "randvib.identification.models": ("MeasurementModel",),
    "randvib.identification.identifiability": ("Identifiability", "IdentifiabilityError"),
    "randvib.identification.identify": ("identify",),
    "randvib.identification.prediction": ("predict_record",),
    "randvib.identification.result": ("IdentificationResult",),
    "randvib.identification.settings": ("SearchSettings", "SimulationSettings"),
    "randvib.identification.assembly_record": ("AssemblyRecord", "assembly_record"),
    "randvib.identification.synthetic": ("synthetic_record",),
    "randvib.montecarlo.integrators": ("Integrator", "INTEGRATORS"),
    "randvib.analytic.linearisation": ("coulomb_equivalent_damping", "equivalent_damping"),
    "randvib.analytic.method": ("AnalyticMethod",),
    "randvib.analytic.power_prediction": ("PowerPrediction",),
    "randvib.analytic.assembly_prediction": (
        "AssemblyLoad",
        "AssemblyPrediction",
        "optimal_assembly_loads",
    ),
    "randvib.analytic.bridge": ("DcOptimum", "optimal_dc_output"),
    "randvib.montecarlo.bridge_optimum": ("simulated_dc_optimum",),
    "randvib.analytic.prediction": (
        "expected_power",
        "METHODS",
        "optimal_load_resistance",
        "optimal_load_resistance_linear",
        "predict",
        "velocity_variance",
    ),
    "randvib.models.presets": ("MAGNET_MASS", "preset", "PRESETS"),
    "randvib.models.record": ("read_record", "Record"),
    "randvib.montecarlo.on_record": ("RecordSimulation", "monte_carlo_on_record"),
    "randvib.montecarlo.spectra": ("SampledSpectra",),
    "randvib.montecarlo.sweep": ("linearisation_verdicts", "run_sweep", "SweepSettings"),
    "randvib.montecarlo.ensembles": ("Case", "EnsembleResult", "run_ensembles"),
    "randvib.montecarlo.event_cases": ("EventSettings",),
    "randvib.studies.spectra_figure": ("plot_response_spectra",),
    "randvib.studies.transient_figure": ("plot_transient",),
    "randvib.identification.sade": ("sade", "SADEResult"),
    "randvib.montecarlo.simulation": ("simulate",),
    "randvib.montecarlo.transient": ("simulate_transient",),
    "randvib.montecarlo.transient_results": ("TransientResult",),
    "randvib.montecarlo.batches": ("SimulationDivergedError",),
    "randvib.montecarlo.results": ("SimulationResult",),
    "randvib.montecarlo.assembly_results": ("AssemblySimulationResult",),
    "randvib.harvester_design.design": ("design",),
    "randvib.harvester_design.result": ("DesignResult",),
    "randvib.analytic.harvesting_limit": (
        "causal_harvesting_limit",
        "gaussian_displacement_budget",
        "harvesting_limit",
        "record_harvesting_limit",
        "record_limit_certificate",
        "RecordLimitCertificate",
        "RecordLimitWarning",
    ),
    "randvib.statistics": ("FirstPassage", "Statistic", "estimate", "TimeStatistics"),
    "randvib.montecarlo.step_check": ("StepSizeWarning",),
    "randvib.montecarlo.reliability": (
        "estimate_first_passage",
        "first_passage",
        "ReliabilityResult",
    ),
    "randvib.montecarlo.path_simulator": ("HarvesterPaths", "PathOutcome", "PathSimulator"),
    "randvib.analytic.crossings": (
        "CROSSING_METHODS",
        "crossing_prediction",
        "CrossingPrediction",
    ),
    "randvib.analytic.gibbs_marginal": ("GibbsDisplacement",),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = sorted(_WHERE, key=str.lower)


def __getattr__(name):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'randvib' has no attribute {name!r}")
    value = getattr(_importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
