"""Fingerprints of the result store's finished entries, for the live SLURM test.

    python .ci/output_snapshot.py record DIR STORE > before.tsv
    python .ci/output_snapshot.py check DIR before.tsv

Every job that computes writes into its own folder of the result store
(DIR/STORE/<rule>-<wildcards>-<key>/, STORE relative to DIR, e.g. results/.store) and
seals it with SHA256SUMS as it ends (docs/store.md). `record` lists every file of
each *finished* entry with its inode, modification time (ns) and SHA-256, the entry's
own log and benchmark file included: an entry is finished when it is sealed
(SHA256SUMS present) and Snakemake marks none of its outputs incomplete. Snakemake
marks a job's outputs incomplete from the job's submission until its success is
recorded (by the job's own Snakemake on the node, or by the submitting one): its file
persistence backend keeps one marker per output in DIR/.snakemake/incomplete/, named
by the output's path in URL-safe base64 (split in chunks of the file-name limit, all
but the last prefixed with "@"). The markers are read before the entries, so a job
that ends in between counts as unfinished; an entry of a job still running (its log
still written) or killed half-way (no seal, or outputs still marked) is left out.
On stderr: how many entries are finished, and how many are not.

`check` exits 1, naming the files, if any listed file is gone or was rewritten (new
inode, time or content): a later run recomputed (or discarded) a finished result.
"""

from __future__ import annotations

import base64
import hashlib
import os
import sys
from pathlib import Path

SEAL = "SHA256SUMS"


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
            path = base64.urlsafe_b64decode(encoded).decode()
            if os.path.isabs(path):
                path = os.path.relpath(path, workdir)
            marked.add(os.path.normpath(path))
    return marked


def fingerprint(path: Path) -> str:
    stat = path.stat()
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    return f"{stat.st_ino}\t{stat.st_mtime_ns}\t{digest}"


def record(workdir: Path, store: str) -> int:
    marked = incomplete_outputs(workdir)  # before the entries: see the docstring
    root = workdir / store
    entries = sorted(p for p in root.iterdir() if p.is_dir()) if root.is_dir() else []
    finished = unfinished = files = 0
    for entry in entries:
        prefix = os.path.relpath(entry, workdir) + os.sep
        if not (entry / SEAL).is_file() or any(m.startswith(prefix) for m in marked):
            unfinished += 1
            continue
        finished += 1
        for path in sorted(entry.rglob("*")):
            if path.is_file() and not path.is_symlink():
                print(f"{path.relative_to(workdir)}\t{fingerprint(path)}")
                files += 1
    print(
        f"{finished} finished entries ({files} files), {unfinished} unfinished"
        f" ({len(marked)} outputs marked incomplete)",
        file=sys.stderr,
    )
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
