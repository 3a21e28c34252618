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
        "chain.errors": "ParameterError",
        "chain.traces": "TraceFormatError read_traces validate_traces write_traces",
        "chain.physics.materials": "MATERIALS Material STEEL_100C6 contact_stiffness "
        "get_material sphere_mass",
        "chain.physics.model": "ChainModel PCB_200B02_STIFFNESS Striker launch_velocities",
        "chain.physics.builders": "build_chain uniform_chain",
        "chain.physics.time_step": "default_time_step",
        "chain.physics.integrator": "IntegrationError integrate",
        "chain.physics.simulation": "SimulationResult simulate",
        "chain.apparatus.shots": "simulate_shots trace_table",
        "chain.analysis.pulses": "ESTIMATORS PulseFit find_pulses fit_pulse",
        "chain.analysis.pulse_rows": "pulse_table",
        "chain.analysis.regression": "fit_fixed_exponent fit_power_law fit_proportional",
        "chain.analysis.delays": "delay_fit_table delay_table",
        "chain.analysis.ssw": "ssw_fit_table ssw_table",
    },
)
