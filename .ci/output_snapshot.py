"""Fingerprints of a run's finished outputs, for the live SLURM test's kill case.

    python .ci/output_snapshot.py record DIR RUN > before.tsv
    python .ci/output_snapshot.py check DIR before.tsv

`record` lists every file under DIR/results/RUN (less logs/ and benchmarks/, which
jobs still running write into) that Snakemake has not marked incomplete, with its
inode, modification time (ns) and SHA-256. A file is marked incomplete from the job's
submission until its success is recorded: Snakemake's file persistence backend keeps
one marker per output in DIR/.snakemake/incomplete/, named by the output's path in
URL-safe base64 (split in chunks of the file-name limit, all but the last prefixed
with "@"). The markers are read before the files, so a job that ends in between
counts as unfinished. `check` exits 1, naming the files, if any listed file is gone
or was rewritten (new inode, time or content): a rerun recomputed a finished output.
"""

from __future__ import annotations

import base64
import hashlib
import os
import sys
from pathlib import Path

SKIPPED = ("logs", "benchmarks")  # written by jobs still running, not outputs


def incomplete_outputs(workdir: Path) -> set[str]:
    """Paths (relative to workdir) that Snakemake marks as incomplete."""
    root = workdir / ".snakemake" / "incomplete"
    marked = set()
    for folder, _, names in os.walk(root):
        for name in names:
            if name == "migration_underway":
                continue
            chunks = Path(folder, name).relative_to(root).parts
            encoded = "".join(chunk.removeprefix("@") for chunk in chunks)
            marked.add(os.path.normpath(base64.urlsafe_b64decode(encoded).decode()))
    return marked


def fingerprint(path: Path) -> str:
    stat = path.stat()
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    return f"{stat.st_ino}\t{stat.st_mtime_ns}\t{digest}"


def record(workdir: Path, run: str) -> int:
    marked = incomplete_outputs(workdir)
    results = workdir / "results" / run
    kept = 0
    for path in sorted(results.rglob("*")):
        relative = path.relative_to(workdir)
        if not path.is_file() or relative.parts[2] in SKIPPED:
            continue
        if str(relative) in marked:
            continue
        print(f"{relative}\t{fingerprint(path)}")
        kept += 1
    print(f"{kept} finished outputs, {len(marked)} marked incomplete", file=sys.stderr)
    return 0


def check(workdir: Path, listing: Path) -> int:
    changed = []
    for line in listing.read_text().splitlines():
        relative, before = line.split("\t", 1)
        path = workdir / relative
        if not path.is_file():
            changed.append(f"{relative} (gone)")
        elif fingerprint(path) != before:
            changed.append(f"{relative} (rewritten)")
    for name in changed:
        print(name)
    return 1 if changed else 0


if __name__ == "__main__":
    command, workdir, argument = sys.argv[1:4]
    if command == "record":
        sys.exit(record(Path(workdir), argument))
    sys.exit(check(Path(workdir), Path(argument)))
