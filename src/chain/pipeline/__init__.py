"""The pipeline glue: the only code that knows ``results/``, and with the studies
(:mod:`chain.studies`) the only code that knows the config's keys. Four rooms, imports
running one way (config <- plan <- run; provenance beside them):

* :mod:`.config`: the checks of a config and their bounds;
* :mod:`.plan`: what runs (the run plan, its jobs, their inputs and resources);
* :mod:`.run`: what happens around Snakemake (the store, checksums, patches);
* :mod:`.provenance`: what made a run, and the headline check.
"""
