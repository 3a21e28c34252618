"""hertzchain: solitary-wave collisions in Hertzian bead chains (Santibanez et al.).

The library behind the pipeline; it knows nothing of Snakemake or config files.
"""

from chain.delays import delay_fit_table, delay_table
from chain.integrator import IntegrationError, integrate
from chain.materials import (
    MATERIALS,
    STEEL_100C6,
    Material,
    ParameterError,
    contact_stiffness,
    get_material,
    sphere_mass,
)
from chain.model import (
    PCB_200B02_STIFFNESS,
    ChainModel,
    Striker,
    build_chain,
    launch_velocities,
    uniform_chain,
)
from chain.pulses import ESTIMATORS, PulseFit, find_pulses, fit_pulse, pulse_table
from chain.regression import fit_fixed_exponent, fit_power_law, fit_proportional
from chain.simulation import (
    SimulationResult,
    default_time_step,
    simulate,
    simulate_shots,
    trace_table,
)
from chain.ssw import ssw_fit_table, ssw_table
from chain.traces import TraceFormatError, read_traces, validate_traces, write_traces

__version__ = "0.1.0"

__all__ = [
    "ESTIMATORS",
    "MATERIALS",
    "PCB_200B02_STIFFNESS",
    "STEEL_100C6",
    "ChainModel",
    "IntegrationError",
    "Material",
    "ParameterError",
    "PulseFit",
    "SimulationResult",
    "Striker",
    "TraceFormatError",
    "build_chain",
    "contact_stiffness",
    "default_time_step",
    "delay_fit_table",
    "delay_table",
    "find_pulses",
    "fit_fixed_exponent",
    "fit_power_law",
    "fit_proportional",
    "fit_pulse",
    "get_material",
    "integrate",
    "launch_velocities",
    "pulse_table",
    "read_traces",
    "simulate",
    "simulate_shots",
    "sphere_mass",
    "ssw_fit_table",
    "ssw_table",
    "trace_table",
    "uniform_chain",
    "validate_traces",
    "write_traces",
]
