"""``hertzchain store``: what the result store holds, and pruning it.

An entry is held by a run folder (``results/<run_name>``) when that folder's
``SHA256SUMS`` lists every file of the entry's outputs, at the path the manifest
records (``paths``, relative to the run folder) and with the stored SHA-256: the run
shows those very bytes. A run folder without ``SHA256SUMS`` (a run going on, or one
that failed before its end) holds nothing. Pruning removes what no run folder holds,
and with a date, what was stored before it whether held or not; each entry goes
through :meth:`chain.pipeline.run.store.Store.discard` (renamed away, then deleted).
"""

from __future__ import annotations

import datetime
from pathlib import Path

from chain.pipeline.run.checksums import CHECKSUMS
from chain.pipeline.run.store import Store


def describe(store: Store) -> str:
    """One line: the store's folder, its number of entries and their size.

    Parameters
    ----------
    store : Store
    """
    sizes = [size for _, _, size in store.entries()]
    return f"result store {store.root}: {len(sizes)} entries, {_bytes(sum(sizes))}"


def run_checksums(results: str | Path) -> list[dict[str, str]]:
    """Each run folder's ``SHA256SUMS``, as path (relative to the run folder) -> SHA-256.

    Parameters
    ----------
    results : path
        The folder of the run folders (``results``); hidden folders (the store) skipped.
    """
    found = []
    for sums in sorted(Path(results).glob(f"[!.]*/{CHECKSUMS}")):
        listed = {}
        for line in sums.read_text().splitlines():
            digest, _, path = line.partition("  ")
            listed[path] = digest
        found.append(listed)
    return found


def held(manifest: dict | None, checksums: list[dict[str, str]]) -> bool:
    """Whether a run folder shows every file of the entry of ``manifest``.

    Parameters
    ----------
    manifest : dict or None
        The entry's manifest (None: unreadable, held by none).
    checksums : list of dict
        :func:`run_checksums`.
    """
    try:
        files = {
            f"{path}/{name}" if name else str(path): sha256
            for path, record in zip(manifest["paths"], manifest["outputs"], strict=True)
            for name, (sha256, _) in record.items()
        }
    except (TypeError, KeyError, ValueError):
        return False
    return any(all(listed.get(p) == d for p, d in files.items()) for listed in checksums)


def prune(store: Store, results: str | Path, older_than=None, dry_run=False) -> list[str]:
    """Remove the entries no run folder under ``results`` holds, and those stored before
    ``older_than`` whether held or not. Returns the console lines: one per entry
    removed, then the count and the bytes freed.

    Parameters
    ----------
    store : Store
    results : path
        The folder of the run folders.
    older_than : datetime.date or None
        Entries stored (the manifest's ``stored``) before this day go too.
    dry_run : bool
        Say what would go and remove nothing.
    """
    checksums = run_checksums(results)
    lines, freed, kept = [], 0, 0
    for key, manifest, size in list(store.entries()):
        stored = _stored(manifest)
        if older_than is not None and stored is not None and stored < older_than:
            why = f"stored {stored}, before {older_than}"
        elif not held(manifest, checksums):
            why = f"held by no run folder under {results}"
        else:
            kept += 1
            continue
        job = (manifest or {}).get("job", "?")
        lines.append(f"  {key[:12]}  {job}  {_bytes(size)}  ({why})")
        freed += size
        if not dry_run:
            store.discard(key)
    done = ("would remove", "freeing") if dry_run else ("removed", "freed")
    return [*lines, f"{done[0]} {len(lines)} entries, {done[1]} {_bytes(freed)}; {kept} kept"]


def _stored(manifest: dict | None) -> datetime.date | None:
    try:
        return datetime.datetime.fromisoformat(manifest["stored"]).date()
    except (TypeError, KeyError, ValueError):
        return None


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
