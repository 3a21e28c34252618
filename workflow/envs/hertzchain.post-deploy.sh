#!/usr/bin/env bash
# Run by Snakemake (--sdm conda) in the new environment of hertzchain.yaml, from the
# working directory (the checkout): the package itself, without dependencies, which the
# lock has installed. (A hash-checked install cannot hold an editable one, so it is not
# in hertzchain.yaml.)
set -euo pipefail
python -m pip install --no-deps -e .
python -m pip check
