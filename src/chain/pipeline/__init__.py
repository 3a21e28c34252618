"""The pipeline glue: the only code that knows ``results/``, and with the studies
(:mod:`chain.studies`) the only code that knows the config's keys.

Cross-key config checks and experiment parts (:mod:`.config`, called by the
Snakefile before any job) and the headline-number check (:mod:`.headline`).
"""
