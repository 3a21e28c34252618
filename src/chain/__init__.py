"""hertzchain: solitary-wave collisions in Hertzian bead chains (Santibanez et al.).

The library behind the pipeline; it knows nothing of Snakemake or config files.
"""

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
from chain.simulation import (
    SimulationResult,
    default_time_step,
    simulate,
    simulate_shots,
    trace_table,
)
from chain.traces import TraceFormatError, read_traces, validate_traces, write_traces

__version__ = "0.1.0"

__all__ = [
    "MATERIALS",
    "PCB_200B02_STIFFNESS",
    "STEEL_100C6",
    "ChainModel",
    "IntegrationError",
    "Material",
    "ParameterError",
    "SimulationResult",
    "Striker",
    "TraceFormatError",
    "build_chain",
    "contact_stiffness",
    "default_time_step",
    "get_material",
    "integrate",
    "launch_velocities",
    "read_traces",
    "simulate",
    "simulate_shots",
    "sphere_mass",
    "trace_table",
    "uniform_chain",
    "validate_traces",
    "write_traces",
]
