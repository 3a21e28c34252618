"""The run's numbers and verdicts, decided once and written to ``summary.json``: the
summary, the paper's own numbers, the claims against the tolerance table, the
ablation, C-spread and mechanism entries. Imports nothing."""
