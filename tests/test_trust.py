"""Who may write a folder (chain.trust): a folder inside the checkout is trusted as the
checkout is, since whoever may write the checkout can change the code the run executes;
a folder outside it is checked with its parents, as before. One console line says when
accounts other than the user may write the checkout, and the run goes on.

The tests with accounts make, as root, a user with a group of its own (a user private
group, as under umask 002 on Ubuntu) and a group with another member (nobody), act as
that user in a subprocess, and remove both after; they are skipped for other users.
"""

from __future__ import annotations

import grp
import json
import os
import pwd
import shutil
import stat
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import pytest

from chain import trust
from chain.pipeline.run.store_path import STORE_VARIABLE, StoreError, open_store

ROOT = Path(__file__).resolve().parents[1]
NOBODY = 65534
IN_TREE_CACHES = shutil.ignore_patterns("__pycache__")


def folders(base: Path, modes: dict[str, int]) -> None:
    """Make the folders ``modes`` names (paths under ``base``, parents first), each with
    its mode whatever the umask."""
    for name, mode in modes.items():
        (base / name).mkdir(exist_ok=True)
        os.chmod(base / name, mode)


def test_a_folder_inside_the_code_no_more_open_than_it_is_trusted(tmp_path):
    """A checkout made under umask 002 (0775, the user's group): its results/.store is
    trusted as the checkout is, a missing one too; checked with its parents, it is not."""
    folders(tmp_path, {"checkout": 0o775, "checkout/results": 0o775, "checkout/results/s": 0o700})
    code = tmp_path / "checkout"
    for folder in (code / "results" / "s", code / "results" / "missing" / "s", code):
        assert trust.trusted(folder, code), folder
        assert trust.problem(folder, code_root=code) is None
    assert trust.problem(code / "results" / "s") == (
        f"{code / 'results'} has mode drwxrwxr-x: its group or others may write in it"
    )


@pytest.mark.parametrize(
    ("modes", "folder"),
    [
        ({"checkout": 0o755, "checkout/results": 0o775}, "checkout/results"),
        ({"checkout": 0o775, "checkout/results": 0o777}, "checkout/results"),
        ({"checkout": 0o1777, "checkout/results": 0o700}, "checkout/results"),
        ({"checkout": 0o755, "elsewhere": 0o700}, "elsewhere"),
        ({"checkout": 0o755, "elsewhere": 0o700}, "checkout/link/store"),
    ],
    ids=["group-writable-in-private", "open-to-all", "sticky-checkout", "outside", "link-out"],
)
def test_a_folder_more_open_than_the_code_or_outside_it_is_not_trusted(tmp_path, modes, folder):
    """More open than the checkout, in a sticky one, outside it, or reached through a
    link that leads out of it: checked with its parents instead."""
    folders(tmp_path, modes)
    (tmp_path / "checkout" / "link").symlink_to(tmp_path / "elsewhere")
    assert not trust.trusted(tmp_path / folder, tmp_path / "checkout")


def test_the_store_in_the_checkout_is_opened_and_one_outside_is_checked_as_before(tmp_path):
    """A store in a umask-002 checkout that the run's code comes from is opened (and
    made private); without that checkout, or outside it under a folder anyone may write
    in, it is refused as before."""
    folders(tmp_path, {"checkout": 0o775, "checkout/results": 0o775, "open": 0o777})
    code, store = tmp_path / "checkout", tmp_path / "checkout" / "results" / ".store"
    open_store({STORE_VARIABLE: str(store)}, trusted=[code])
    assert stat.S_IMODE(store.stat().st_mode) == 0o700
    with pytest.raises(StoreError, match=f"{code}.* has mode drwxrwxr-x"):
        open_store({STORE_VARIABLE: str(store)})
    outside = tmp_path / "open" / "store"
    with pytest.raises(StoreError, match=f"{tmp_path / 'open'} has mode drwxrwxrwx"):
        open_store({STORE_VARIABLE: str(outside)}, trusted=[code])
    assert not outside.exists()


@pytest.mark.parametrize("mode", [0o755, 0o700, 0o757, 0o777])
def test_a_checkout_everyone_may_write_gets_one_line(tmp_path, mode):
    """Writable by others: one line naming the checkout and the fix; else none (a
    group-writable checkout: see the tests with accounts)."""
    folders(tmp_path, {"checkout": mode})
    line = trust.open_code_line(tmp_path / "checkout")
    if mode & 0o002:
        assert "accounts other than you can change the code this run executes" in line
        assert f"`chmod -R g-w,o-w {tmp_path / 'checkout'}`" in line
        assert "the run goes on" in line
    else:
        assert line is None


# ---- as another user, with a group of its own -------------------------------------------

#: Run as the test user in its checkout (argv[1]): what the rule says of it.
REPORT = """
import json, os, sys
from pathlib import Path
from chain import trust
from chain.physics import safe_cache
from chain.pipeline.run.store_path import StoreError, open_store
checkout = Path(sys.argv[1])
physics = checkout / "src" / "chain" / "physics"
folder, problem = safe_cache.cache_folder(str(physics))
try:
    os.chdir(checkout)
    open_store(os.environ, trusted=[checkout])
    store = None
except StoreError as error:
    store = str(error)
print(json.dumps({"line": trust.open_code_line(checkout), "cache": str(folder),
                  "cache_problem": problem, "store": store}))
"""


#: Pythons another account may run (this one may sit in root's home), given this one's
#: packages on PYTHONPATH.
PYTHONS = [sys.executable, "/usr/bin/python{}.{}".format(*sys.version_info[:2])]
PACKAGES = sysconfig.get_paths()["purelib"]


def run_as(account: dict, args: list[str], cwd: Path, env: dict | None = None):
    """``args`` (a Python command line) as the test user, under umask 002, no stdin;
    the library from ``cwd/src`` unless ``env`` says otherwise."""
    env = {"PYTHONPATH": str(cwd / "src"), **(env or {})}
    env["PYTHONPATH"] += os.pathsep + PACKAGES
    return subprocess.run(
        [account["python"], *args], user=account["uid"], group=account["gid"],
        extra_groups=account["groups"], umask=0o002, cwd=cwd, stdin=subprocess.DEVNULL,
        env={"PATH": os.defpath, "HOME": str(account["home"]), **env},
        capture_output=True, text=True, check=False,
    )  # fmt: skip


def python_of(account: dict) -> str | None:
    """The first of :data:`PYTHONS` the test user can run Snakemake and numba with."""
    for python in PYTHONS:
        try:
            account["python"] = python
            if run_as(account, ["-c", "import numba, snakemake"], account["home"]).returncode == 0:
                return python
        except OSError:
            continue
    return None


@pytest.fixture
def account():
    """A user with a private group (named as it, no one else in it), its home and a
    checkout of its own made under umask 002 in a folder all may read; removed after."""
    if os.geteuid() != 0 or not all(map(shutil.which, ("useradd", "userdel", "groupadd"))):
        pytest.skip("needs root, useradd, userdel and groupadd to make a second account")
    name = f"hzt{os.getpid()}{os.urandom(2).hex()}"
    base = Path(tempfile.mkdtemp(prefix="hertzchain-trust-", dir="/tmp"))
    os.chmod(base, 0o755)
    home = base / "home"
    subprocess.run(["useradd", "-U", "-M", "-d", str(home), name], check=True, capture_output=True)
    try:
        info = pwd.getpwnam(name)
        home.mkdir(mode=0o700)
        os.chown(home, info.pw_uid, info.pw_gid)
        acct = {"name": name, "uid": info.pw_uid, "gid": info.pw_gid, "groups": [],
                "home": home, "base": base}  # fmt: skip
        if python_of(acct) is None:
            pytest.skip(f"{name} can run none of {PYTHONS} with numba and Snakemake")
        acct["checkout"] = clone(acct)
        yield acct
    finally:
        subprocess.run(["userdel", name], capture_output=True)
        subprocess.run(["groupdel", name], capture_output=True)
        shutil.rmtree(base)


#: What a clone holds that a run reads; copied as ``git clone`` makes files (umask).
CLONED = ["Snakefile", "config.yaml", "workflow", "profiles", "src/chain"]
COPY = """
import os, shutil, sys
from pathlib import Path
source, target = Path(sys.argv[1]), Path(sys.argv[2])
for name in sys.argv[3:]:
    for path in [source / name, *sorted((source / name).rglob("*"))]:
        if "__pycache__" in path.parts:
            continue
        out = target / path.relative_to(source)
        if path.is_dir():
            out.mkdir(parents=True)
        else:
            out.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, out)
"""


def clone(account: dict) -> Path:
    """A checkout of the test user's, made under umask 002: folders 0775, files 0664."""
    checkout = account["home"] / "hertzchain"
    done = run_as(account, ["-c", COPY, str(ROOT), str(checkout), *CLONED], cwd=account["home"])
    assert done.returncode == 0, done.stderr
    assert stat.S_IMODE(checkout.stat().st_mode) == 0o775
    return checkout


def report(account: dict, env: dict | None = None) -> dict:
    done = run_as(account, ["-c", REPORT, str(account["checkout"])], account["checkout"], env)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def dry_run(account: dict) -> subprocess.CompletedProcess:
    """``snakemake -n`` in the test user's checkout, as that user."""
    done = run_as(account, ["-m", "snakemake", "-n", "--cores", "1"], account["checkout"])
    assert done.returncode == 0, (done.stdout + done.stderr)[-3000:]
    return done


def test_a_umask_002_clone_of_a_private_group_is_trusted_and_says_nothing(account):
    """The user's own clone under umask 002 (0775, group its own): the store in it and
    the package's __pycache__ are used, and no line is said, in a dry run either."""
    checkout = account["checkout"]
    (checkout / "results").mkdir()
    os.chown(checkout / "results", account["uid"], account["gid"])
    os.chmod(checkout / "results", 0o775)
    said = report(account)
    physics = checkout / "src" / "chain" / "physics"
    assert said == {"line": None, "cache": str(physics / "__pycache__"), "cache_problem": None,
                    "store": None}  # fmt: skip
    assert stat.S_IMODE((physics / "__pycache__").stat().st_mode) == 0o775
    assert (checkout / "results" / ".store").is_dir()
    assert "accounts other than you" not in dry_run(account).stderr


def test_a_checkout_a_group_with_another_member_may_write_gets_one_line(account):
    """The same clone made writable by a group with nobody in it: one line naming it and
    the fix, and the run goes on (a dry run, the store, numba's cache)."""
    if not shutil.which("gpasswd"):
        pytest.skip("needs gpasswd to put another account in a group")
    lab = f"hzl{os.getpid()}{os.urandom(2).hex()}"
    subprocess.run(["groupadd", lab], check=True, capture_output=True)
    try:
        for member in ("nobody", account["name"]):
            subprocess.run(["gpasswd", "-a", member, lab], check=True, capture_output=True)
        gid = grp.getgrnam(lab).gr_gid
        account["groups"] = [gid]
        for path in [account["checkout"], *account["checkout"].rglob("*")]:
            os.lchown(path, -1, gid)
        said = report(account)
        assert said["line"].startswith(f"hertzchain: {account['checkout']} has mode drwxrwxr-x")
        assert said["cache_problem"] is None and said["store"] is None
        lines = dry_run(account).stderr.splitlines()
        assert len([line for line in lines if "accounts other than you" in line]) == 1, lines
    finally:
        subprocess.run(["groupdel", lab], capture_output=True)


def test_a_folder_of_another_account_or_anyone_outside_the_clone_is_refused(account):
    """In the trusted clone, HERTZCHAIN_STORE and NUMBA_CACHE_DIR outside it are checked
    with their parents, as before: under a folder anyone may write (not sticky), or of
    another account, they are refused."""
    base = account["base"]
    folders(base, {"open": 0o777, "nobody": 0o777})
    os.chown(base / "nobody", NOBODY, NOBODY)
    for where, owner in ((base / "open", "drwxrwxrwx"), (base / "nobody", "uid 65534")):
        env = {STORE_VARIABLE: str(where / "store"), "NUMBA_CACHE_DIR": str(where / "numba")}
        said = report(account, env)
        assert said["store"].startswith(f"result store {where / 'store'}: {where} ")
        assert owner in said["store"] and owner in said["cache_problem"]
        assert said["cache"].startswith(str(where / "numba" / "physics_"))
    assert sorted(p.name for p in base.iterdir()) == ["home", "nobody", "open"]
    assert not list((base / "open").iterdir()) and not list((base / "nobody").iterdir())


def test_numba_caches_a_read_only_install_in_a_private_folder_of_the_user(account):
    """Sources the user may not write (root's, as a system-wide install): the kernels'
    cache goes to a folder of the user's under ~/.cache/numba, made 0700."""
    site = account["base"] / "site"
    shutil.copytree(ROOT / "src" / "chain", site / "chain", ignore=IN_TREE_CACHES)
    for path in [site, *site.rglob("*")]:
        os.chmod(path, 0o755 if path.is_dir() else 0o644)
    code = "import sys; from chain.physics.safe_cache import *; print(cache_folder(sys.argv[1]))"
    done = run_as(account, ["-B", "-c", code, str(site / "chain" / "physics")], account["home"],
                  {"PYTHONPATH": str(site)})  # fmt: skip
    assert done.returncode == 0, done.stderr
    cache = account["home"] / ".cache" / "numba"
    assert f"{cache}/physics_" in done.stdout and "None)" in done.stdout
    made = [account["home"] / ".cache", cache, *cache.iterdir()]
    assert [stat.S_IMODE(p.stat().st_mode) for p in made] == [0o700] * 3
    assert not (site / "chain" / "physics" / "__pycache__").exists()
