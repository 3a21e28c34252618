"""``hertzchain store``: what the result store holds, and pruning it.

An entry is held by a run folder (``results/<run_name>``) when the folder shows one of
its files (its ``SHA256SUMS`` lists the same SHA-256) or the entry is upstream of one
that it shows (:func:`chain.pipeline.run.publish.upstream`). A run folder without
``SHA256SUMS`` (a run going on, or one that failed before its end) holds nothing.
Pruning removes what no run folder holds, and with a date, what was stored before it
whether held or not.
"""

from __future__ import annotations

import datetime
import os
from pathlib import Path

from chain.pipeline.provenance.checksums import CHECKSUMS
from chain.pipeline.run.entries import ENTRY, SUMS, discard, read_sums
from chain.pipeline.run.publish import upstream


def entries(store: str | Path) -> list[tuple[Path, int]]:
    """(folder, size in bytes) of each sealed entry of the store, sorted."""
    found = []
    root = Path(os.path.abspath(store))  # as entry_of and upstream name them
    for entry in sorted(root.iterdir()) if root.is_dir() else []:
        if ENTRY.match(entry.name) and (entry / SUMS).is_file():
            size = sum(p.lstat().st_size for p in entry.rglob("*") if p.is_file())
            found.append((entry, size))
    return found


def describe(store: str | Path) -> str:
    """One line: the store's folder, its number of entries and their size."""
    sizes = [size for _, size in entries(store)]
    return f"result store {store}: {len(sizes)} entries, {_bytes(sum(sizes))}"


def held(store: str | Path, results: str | Path) -> set[Path]:
    """The entries some run folder under ``results`` holds (see the module's docstring)."""
    shown = set()
    for sums in Path(results).glob(f"[!.]*/{CHECKSUMS}"):
        shown |= {line.partition("  ")[0] for line in sums.read_text().splitlines()}
    showing = {entry for entry, _ in entries(store)
               if any(d in shown for n, d in _own(entry).items())}  # fmt: skip
    return set(upstream(showing))


def _own(entry: Path) -> dict[str, str]:
    return {name: d for name, d in read_sums(entry).items() if not name.startswith("../")}


def prune(store: str | Path, results: str | Path, older_than=None, dry_run=False) -> list[str]:
    """Remove the entries no run folder under ``results`` holds, and those stored before
    ``older_than`` whether held or not. Returns the console lines: one per entry
    removed, then the count and the bytes freed.

    Parameters
    ----------
    store : path
        The store's folder.
    results : path
        The folder of the run folders.
    older_than : datetime.date or None
        Entries stored (sealed) before this day go too.
    dry_run : bool
        Say what would go and remove nothing.
    """
    keep = held(store, results)
    lines, freed, kept = [], 0, 0
    for entry, size in entries(store):
        stored = datetime.date.fromtimestamp(os.stat(entry / SUMS).st_mtime)
        if older_than is not None and stored < older_than:
            why = f"stored {stored}, before {older_than}"
        elif entry not in keep:
            why = f"held by no run folder under {results}"
        else:
            kept += 1
            continue
        lines.append(f"  {entry.name}  {_bytes(size)}  ({why})")
        freed += size
        if not dry_run:
            discard(entry)
    done = ("would remove", "freeing") if dry_run else ("removed", "freed")
    return [*lines, f"{done[0]} {len(lines)} entries, {done[1]} {_bytes(freed)}; {kept} kept"]


def _bytes(count: int) -> str:
    """A size for people, with the exact count of bytes."""
    if count < 1000:
        return f"{count} B"
    size, unit = count / 1000, "kB"
    for bigger in ("MB", "GB", "TB"):
        if size < 1000:
            break
        size, unit = size / 1000, bigger
    return f"{size:.1f} {unit} ({count} bytes)"
