"""The apparatus: how traces come to be.

Simulated shots (:mod:`.shots`), the acquisition chain (:mod:`.acquisition`), the
virtual experiment, a model of the paper's apparatus (:mod:`.virtual`), and the
reader of a lab's measured datasets (:mod:`.measured`).
"""

from chain._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "chain.apparatus.shots": "simulate_shots trace_table",
        "chain.apparatus.virtual": "VirtualExperiment run_virtual_experiment",
        "chain.apparatus.measured": "MeasuredDataError load_dataset read_metadata",
    },
)
