"""hertzchain: solitary-wave collisions in Hertzian bead chains (Santibanez et al.).

The library behind the pipeline; it knows nothing of Snakemake or config files.
Its wings, each importing only the ones below it (``tests/test_layering.py``):

* :mod:`chain.errors`, :mod:`chain.atomic`, :mod:`chain.traces`, :mod:`chain.labels`:
  the error type and input checks, atomic writes, the one trace format, labels;
* :mod:`chain.physics`: materials, chain model, integrator, closed forms;
* :mod:`chain.apparatus`: simulated shots, acquisition, virtual experiment, measured data;
* :mod:`chain.analysis`: pulses, selection, delays, SSW, regression, row hygiene;
* :mod:`chain.report`: figures and the summary;
* :mod:`chain.studies`: ablation, C sensitivity, sweep and mechanism studies, simulated
  and analysed in-process;
* :mod:`chain.pipeline`: the workflow glue, config checks and the headline check (with
  the studies, the only config-aware code).

The public names below are imported on first use, so ``import chain`` is cheap.
"""

from chain._lazy import lazy_exports

__version__ = "0.1.0"

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "ChainModel": "chain.physics.model",
        "ESTIMATORS": "chain.analysis.pulses",
        "IntegrationError": "chain.physics.integrator",
        "MATERIALS": "chain.physics.materials",
        "Material": "chain.physics.materials",
        "PCB_200B02_STIFFNESS": "chain.physics.model",
        "ParameterError": "chain.errors",
        "PulseFit": "chain.analysis.pulses",
        "STEEL_100C6": "chain.physics.materials",
        "SimulationResult": "chain.physics.simulation",
        "Striker": "chain.physics.model",
        "TraceFormatError": "chain.traces",
        "build_chain": "chain.physics.builders",
        "contact_stiffness": "chain.physics.materials",
        "default_time_step": "chain.physics.time_step",
        "delay_fit_table": "chain.analysis.delays",
        "delay_table": "chain.analysis.delays",
        "find_pulses": "chain.analysis.pulses",
        "fit_fixed_exponent": "chain.analysis.regression",
        "fit_power_law": "chain.analysis.regression",
        "fit_proportional": "chain.analysis.regression",
        "fit_pulse": "chain.analysis.pulses",
        "get_material": "chain.physics.materials",
        "integrate": "chain.physics.integrator",
        "launch_velocities": "chain.physics.model",
        "pulse_table": "chain.analysis.pulse_rows",
        "read_traces": "chain.traces",
        "simulate": "chain.physics.simulation",
        "simulate_shots": "chain.apparatus.shots",
        "sphere_mass": "chain.physics.materials",
        "ssw_fit_table": "chain.analysis.ssw",
        "ssw_table": "chain.analysis.ssw",
        "trace_table": "chain.apparatus.shots",
        "uniform_chain": "chain.physics.builders",
        "validate_traces": "chain.traces",
        "write_traces": "chain.traces",
    },
)
