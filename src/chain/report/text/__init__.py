"""The run's text: ``summary.md`` and the article, formatted from ``summary.json``
(verdicts, ratios and names are read, never decided here). Imports nothing."""
