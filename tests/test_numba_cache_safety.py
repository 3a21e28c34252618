"""numba's cache of the kernels is never read from a folder another account can write
(chain.physics.safe_cache).

numba unpickles a kernel's cache index before any check: an index planted by another
account runs its code. Shown with a planted index whose code only writes a marker file:
numba runs it from a folder it trusts, and chain's kernels never read it from a folder
of another account. The attack needs a folder owned by another user: as root, made here
and given to uid 65534 (nobody); those tests are skipped for other users. The sources'
own __pycache__ is trusted as the sources are (chain.trust): one more open than them is
passed over for a private folder of the user's.
"""

from __future__ import annotations

import hashlib
import inspect
import os
import pickle
import stat
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import chain
from chain import trust
from chain.physics import kernels, safe_cache
from chain.physics.kernel_cache import SOURCES, sources_digest

PHYSICS = Path(kernels.__file__).parent
NOBODY = 65534
as_root = pytest.mark.skipif(
    os.geteuid() != 0, reason="needs root, to give a folder to another account (chown)"
)


def bits(result) -> str:
    """SHA-256 of every array of a simulation result, in order."""
    arrays = [value for value in vars(result).values() if isinstance(value, np.ndarray)]
    return hashlib.sha256(b"".join(array.tobytes() for array in arrays)).hexdigest()


#: A fresh process: the library's collision on a short chain; its bits, then how numba
#: got the step loop (cache hits, cache misses, cache folder).
JOB = f"""
import hashlib
import numpy as np
import chain
from chain.physics import kernels
{inspect.getsource(bits)}
result = chain.simulate(chain.uniform_chain(26), 0.3, 0.3, duration=1e-5)
stats = kernels._integrate_part.stats
hits, misses = sum(stats.cache_hits.values()), sum(stats.cache_misses.values())
print(bits(result), hits, misses, stats.cache_path)
"""


def run(code: str, cache_dir: Path) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter with NUMBA_CACHE_DIR ``cache_dir``, no stdin."""
    done = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, "NUMBA_CACHE_DIR": str(cache_dir)},
        stdin=subprocess.DEVNULL, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return done


@pytest.fixture(scope="module")
def safe_bits() -> str:
    """The bits of :data:`JOB`'s collision in this process (its cache is safe)."""
    return bits(chain.simulate(chain.uniform_chain(26), 0.3, 0.3, duration=1e-5))


class Planted:
    """A pickle that, loaded, opens ``marker`` for writing (creates an empty file)."""

    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def plant(cache_dir: Path, marker: Path) -> Path:
    """An index of the step loop that writes ``marker`` when unpickled, in numba's
    folder for the kernels under ``cache_dir``, with the digest that
    chain.physics.kernel_cache keeps beside it (else it removes the index first)."""
    folder = cache_dir / numba.core.caching._CacheLocator.get_suitable_cache_subpath(
        kernels.__file__
    )
    folder.mkdir(parents=True)
    for made in (cache_dir, folder):
        made.chmod(0o700)  # whatever the umask
    index = kernels._integrate_part._cache._cache_file._index_name
    (folder / index).write_bytes(pickle.dumps(Planted(marker)))
    (folder / "kernels.sources.sha256").write_text(sources_digest(PHYSICS / s for s in SOURCES))
    return folder


def private_folder(path: Path) -> Path:
    """A new folder for the test, no one else's, its chain of folders checked."""
    path.mkdir(mode=0o700)
    if trust.problem(path):
        pytest.skip(f"the temporary folder is not private here: {trust.problem(path)}")
    return path


def test_numba_runs_a_planted_index_from_a_folder_it_trusts(tmp_path):
    """The attack is real: from a folder of ours, numba unpickles the planted index
    when it looks for the step loop in its cache, and the marker appears."""
    work = private_folder(tmp_path / "work")
    plant(work / "numba", work / "marker")
    run("from chain.physics import kernels\n"
        "kernels._integrate_part._cache._cache_file._load_index()", work / "numba")  # fmt: skip
    assert (work / "marker").exists()


@as_root
def test_a_planted_index_in_a_folder_of_another_account_is_never_loaded(tmp_path, safe_bits):
    """Another account made NUMBA_CACHE_DIR first and planted an index: the library
    compiles without the cache, says so on one line naming the folder and its owner,
    writes nothing there, and computes the same bits."""
    work = private_folder(tmp_path / "work")
    cache_dir = work / "numba"
    folder = plant(cache_dir, work / "marker")
    for path in [cache_dir, *cache_dir.rglob("*")]:
        os.chown(path, NOBODY, NOBODY)
    before = sorted(folder.iterdir())
    done = run(JOB, cache_dir)
    assert not (work / "marker").exists()
    said = [line for line in done.stderr.splitlines() if "numba's cache folder" in line]
    assert len(said) == 1, done.stderr
    assert str(folder) in said[0] and f"is owned by uid {NOBODY}" in said[0], said
    assert "mkdir -m 700" in said[0]
    assert sorted(folder.iterdir()) == before  # no digest, no lock file
    assert done.stdout.split() == [safe_bits, "0", "1", "None"]  # no cache at all


def test_a_private_cache_folder_is_used(tmp_path, safe_bits):
    """NUMBA_CACHE_DIR missing: made 0700; the second process loads the step loop the
    first compiled, with the same bits, and nothing is said."""
    work = private_folder(tmp_path / "work")
    first = run(JOB, work / "numba")
    second = run(JOB, work / "numba")
    folder = str(next((work / "numba").iterdir()))
    assert first.stdout.split() == [safe_bits, "0", "1", folder], first.stdout
    assert second.stdout.split() == [safe_bits, "1", "0", folder], second.stdout
    assert "numba's cache folder" not in first.stderr + second.stderr
    made = [work / "numba", *(work / "numba").iterdir()]
    assert [stat.S_IMODE(path.stat().st_mode) for path in made] == [0o700, 0o700]


@pytest.mark.parametrize(
    ("parent_mode", "problem"),
    [(0o775, "drwxrwxr-x"), (0o757, "drwxr-xrwx"), (0o777, "drwxrwxrwx"), (0o1777, None)],
    ids=["group-writable", "others-writable", "world-writable", "sticky"],
)
def test_a_parent_others_may_write_in_is_refused(tmp_path, monkeypatch, parent_mode, problem):
    """NUMBA_CACHE_DIR in a folder that others may write in (not sticky): refused, and
    the cache folder is not made there; below a sticky one (/tmp): made and used."""
    parent = private_folder(tmp_path / "shared")
    parent.chmod(parent_mode)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(parent / "numba"))
    folder, found = safe_cache.cache_folder(str(PHYSICS))
    assert folder.parent == parent / "numba"
    if problem is None:
        assert found is None and folder.is_dir()
    else:
        assert found == f"{parent} has mode {problem}: its group or others may write in it"
        assert not (parent / "numba").exists()


def test_the_cache_folder_itself_is_never_shared(tmp_path):
    """Sticky or not, a cache folder that others may write in is refused (anyone may add
    an index to it)."""
    folder = private_folder(tmp_path / "numba")
    folder.chmod(0o1777)
    assert (
        trust.problem(folder)
        == f"{folder} has mode drwxrwxrwt: its group or others may write in it"
    )


def test_the_console_names_the_folder_and_the_fix(tmp_path, monkeypatch, capsys):
    parent = private_folder(tmp_path / "shared")
    parent.chmod(0o777)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(parent / "numba"))
    assert not safe_cache._verdict.__wrapped__(str(PHYSICS))
    said = capsys.readouterr().err.splitlines()
    assert len(said) == 1 and str(parent / "numba" / "physics_") in said[0], said
    assert "drwxrwxrwx" in said[0] and "mkdir -m 700" in said[0] and "unset it" in said[0]


def test_the_folder_is_the_one_numba_uses(tmp_path, monkeypatch):
    """The folder checked is the one numba's own dispatcher picks: with NUMBA_CACHE_DIR
    (made 0700 at each missing level) and for the kernels as this process has them."""
    assert kernels._integrate_part._cache.cache_path == str(
        safe_cache.cache_folder(str(PHYSICS))[0]
    )
    work = private_folder(tmp_path / "work")
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(work / "a" / "b"))
    folder, problem = safe_cache.cache_folder(str(Path(__file__).parent))
    assert problem is None
    made = [work / "a", work / "a" / "b", folder]
    assert [stat.S_IMODE(path.stat().st_mode) for path in made] == [0o700] * 3
    assert numba.njit(cache=True)(bits)._cache.cache_path == str(folder)


@as_root
def test_a_link_of_another_account_is_refused(tmp_path):
    """A symbolic link on the way that another account owns (it could point it
    elsewhere, in a sticky folder) is refused, though its target is ours."""
    work = private_folder(tmp_path / "work")
    target = private_folder(work / "target")
    link = work / "link"
    link.symlink_to(target)
    assert trust.problem(link) is None
    os.lchown(link, NOBODY, NOBODY)
    assert trust.problem(link) == f"{link} is owned by uid {NOBODY} (nobody)"


def test_every_cached_kernel_asks_first():
    """No kernel of the library is decorated with a cache before the folder is checked."""
    for path in sorted(Path(chain.__file__).parent.rglob("*.py")):
        text = path.read_text()
        assert "cache=True" not in text, path
        if "cache=CACHE" in text:
            assert "CACHE = safe_cache.allowed(__file__)" in text, path


#: A module of one cached kernel, run twice: where its cache is, and whether it was hit.
MODULE = """
import numba
from chain.physics import safe_cache
CACHE = safe_cache.allowed(__file__)
@numba.njit(cache=CACHE)
def add_one(x):
    return x + 1
add_one(1)
print(add_one._cache.cache_path, sum(add_one.stats.cache_hits.values()))
"""


@pytest.mark.parametrize(
    ("sources_mode", "pycache_mode", "in_tree"),
    [(0o775, 0o775, True), (0o755, 0o755, True), (0o755, 0o775, False), (0o755, 0o777, False)],
    ids=["umask-002-clone", "umask-022-clone", "group-writable-pycache", "open-pycache"],
)
def test_pycache_is_trusted_as_its_sources_are(tmp_path, sources_mode, pycache_mode, in_tree):
    """A __pycache__ no more open than its sources (a clone made under umask 002 or 022)
    is used; one more open is passed over for a folder of the user's under their cache
    directory, made 0700, where the second process finds what the first compiled.
    Nothing is said either way, and nothing is written in a __pycache__ passed over."""
    work = private_folder(tmp_path / "work")
    sources = work / "src"
    sources.mkdir()
    (sources / "kernel.py").write_text(MODULE)
    (sources / "__pycache__").mkdir()
    sources.chmod(sources_mode)
    (sources / "__pycache__").chmod(pycache_mode)
    env = {**os.environ, "XDG_CACHE_HOME": str(work / "cache")}
    env.pop("NUMBA_CACHE_DIR", None)
    command = [sys.executable, "-B", str(sources / "kernel.py")]
    done = [
        subprocess.run(command, env=env, stdin=subprocess.DEVNULL, capture_output=True, text=True)
        for _ in range(2)
    ]
    folder = sources / "__pycache__"
    if not in_tree:
        subpath = numba.core.caching._CacheLocator.get_suitable_cache_subpath(str(sources / "_.py"))
        folder = work / "cache" / "numba" / subpath
        made = [work / "cache", work / "cache" / "numba", folder]
        assert [stat.S_IMODE(path.stat().st_mode) for path in made] == [0o700] * 3
        assert list((sources / "__pycache__").iterdir()) == []
    said = [run.stdout.split() for run in done]
    assert said == [[str(folder), "0"], [str(folder), "1"]], [run.stderr for run in done]
    assert not "".join(run.stderr for run in done)
