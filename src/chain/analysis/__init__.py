"""The analysis: traces and tables to numbers. It draws nothing and simulates nothing.

Pulses (cos^6 fits), the acceptance protocol (:mod:`.selection`), delays and their
fits, secondary solitary waves, regression, and row hygiene (:mod:`.rows`).
"""

from chain._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        **dict.fromkeys(
            ["ESTIMATORS", "PulseFit", "find_pulses", "fit_pulse"],
            "chain.analysis.pulses",
        ),
        **dict.fromkeys(
            ["fit_fixed_exponent", "fit_power_law", "fit_proportional"],
            "chain.analysis.regression",
        ),
        "pulse_table": "chain.analysis.pulse_rows",
        **dict.fromkeys(["delay_fit_table", "delay_table"], "chain.analysis.delays"),
        **dict.fromkeys(["ssw_fit_table", "ssw_table"], "chain.analysis.ssw"),
        **dict.fromkeys(["apply_selection", "select_shots"], "chain.analysis.selection"),
        **dict.fromkeys(["is_ok", "usable_rows"], "chain.analysis.rows"),
    },
)
