"""The physics: materials, the chain model, the integrator, the closed forms.

numpy, scipy and numba only: no pandas, no files, nothing from the other wings.
"""

from chain._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "chain.physics.materials": "MATERIALS STEEL_100C6 Material contact_stiffness "
        "get_material sphere_mass",
        "chain.physics.model": "PCB_200B02_STIFFNESS ChainModel Striker launch_velocities",
        "chain.physics.builders": "build_chain uniform_chain",
        "chain.physics.integrator": "IntegrationError integrate integrate_many",
        "chain.physics.simulation": "SimulationResult simulate simulate_many",
        "chain.physics.time_step": "default_time_step",
    },
)
