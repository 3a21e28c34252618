"""The analysis: traces and tables to numbers. It draws nothing and simulates nothing.

Pulses (cos^6 fits), the acceptance protocol (:mod:`.selection`), delays and their
fits, secondary solitary waves, regression, and row hygiene (:mod:`.rows`).
"""

from chain._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "chain.analysis.pulses": "ESTIMATORS PulseFit find_pulses fit_pulse",
        "chain.analysis.regression": "fit_fixed_exponent fit_power_law fit_proportional",
        "chain.analysis.pulse_rows": "pulse_table",
        "chain.analysis.delays": "delay_fit_table delay_table",
        "chain.analysis.ssw": "ssw_fit_table ssw_table",
        "chain.analysis.selection": "apply_selection select_shots",
        "chain.analysis.rows": "is_ok usable_rows",
    },
)
