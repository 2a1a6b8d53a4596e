"""randvib: random-vibration analysis of nonlinear energy harvesters with friction.

Implements and extends Green, Worden & Sims, "On the identification and
modelling of friction in a randomly excited energy harvester". SI units
throughout; S is the one-sided PSD of the base acceleration in (m/s^2)^2/Hz.
"""

from randvib.averaging import (
    AveragingValidityWarning,
    averaging_statistics,
    energy_density,
    orbit_averages,
)
from randvib.deterministic import BatchSimulation, simulate_record
from randvib.excitation import BaseExcitation, band_limited_excitation
from randvib.fokker_planck import fast_fpk_statistics, fpk_statistics, solve_fpk
from randvib.friction import Coulomb, FrictionModel, LuGre, Tanh
from randvib.harvester import ElectricalCoupling, Harvester
from randvib.identification import (
    IdentificationResult,
    Record,
    identify,
    normalised_cost,
    read_record,
)
from randvib.integrators import INTEGRATORS, Integrator
from randvib.linearisation import coulomb_equivalent_damping, equivalent_damping
from randvib.prediction import (
    METHODS,
    PowerPrediction,
    expected_power,
    optimal_load_resistance,
    optimal_load_resistance_linear,
    predict,
    velocity_variance,
)
from randvib.presets import MAGNET_MASS, PRESETS, preset
from randvib.sade import SADEResult, sade
from randvib.simulation import (
    SimulationDivergedError,
    SimulationResult,
    Statistic,
    StepSizeWarning,
    simulate,
)

__version__ = "0.1.0"

__all__ = [
    "AveragingValidityWarning",
    "BaseExcitation",
    "BatchSimulation",
    "Coulomb",
    "ElectricalCoupling",
    "FrictionModel",
    "Harvester",
    "IdentificationResult",
    "INTEGRATORS",
    "Integrator",
    "LuGre",
    "MAGNET_MASS",
    "METHODS",
    "PRESETS",
    "PowerPrediction",
    "Record",
    "SADEResult",
    "SimulationDivergedError",
    "SimulationResult",
    "Statistic",
    "StepSizeWarning",
    "Tanh",
    "band_limited_excitation",
    "coulomb_equivalent_damping",
    "equivalent_damping",
    "expected_power",
    "identify",
    "normalised_cost",
    "optimal_load_resistance",
    "optimal_load_resistance_linear",
    "predict",
    "preset",
    "read_record",
    "sade",
    "simulate",
    "simulate_record",
    "velocity_variance",
    "averaging_statistics",
    "energy_density",
    "fast_fpk_statistics",
    "fpk_statistics",
    "orbit_averages",
    "solve_fpk",
]
