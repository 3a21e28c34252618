"""The code inputs of a rule (chain.pipeline.plan.code): the package files its script runs,
and the store that spares the next command parsing them again."""

from __future__ import annotations

import os

import pytest

from chain.pipeline.plan import code as deps


@pytest.fixture
def fresh_process():
    """deps as a new process finds it: nothing parsed, nothing remembered."""

    def reset():
        deps._parsed_imports.cache_clear()
        deps._package_closure.cache_clear()
        deps._KNOWN.clear()
        deps._UNSAVED.clear()

    reset()
    yield reset
    reset()


@pytest.fixture
def checkout(tmp_path, monkeypatch):
    """A package ``chain`` of three modules and a script importing one of them."""
    package = tmp_path / "src" / "chain"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("from chain.b import g\n\ndef f():\n    return g()\n")
    (package / "b.py").write_text("def g():\n    return 1\n")
    (package / "c.py").write_text("def h():\n    return 2\n")
    script = tmp_path / "script.py"
    script.write_text("from chain.a import f\n")
    monkeypatch.chdir(tmp_path)
    return script, package


def test_the_store_gives_the_next_process_the_same_files_unparsed(
    checkout, fresh_process, tmp_path, monkeypatch
):
    script, package = checkout
    store = tmp_path / ".snakemake" / "hertzchain" / "imports.json"
    deps.remember_imports(store)  # none yet
    first = deps.script_sources(script, package)
    assert first == [os.path.join("src", "chain", n) for n in ("__init__.py", "a.py", "b.py")]
    deps.save_imports(store)
    assert store.is_file()

    fresh_process()
    deps.remember_imports(store)

    def parse(path):
        raise AssertionError(f"{path} parsed again")

    monkeypatch.setattr(deps, "_read_imports", parse)
    assert deps.script_sources(script, package) == first


def test_a_changed_file_is_read_again(checkout, fresh_process, tmp_path):
    script, package = checkout
    store = tmp_path / "imports.json"
    deps.remember_imports(store)
    assert os.path.join("src", "chain", "c.py") not in deps.script_sources(script, package)
    deps.save_imports(store)

    fresh_process()
    # One more import: a new size (and time); the store's entry no longer matches.
    (package / "b.py").write_text("from chain.c import h\n\ndef g():\n    return h()\n")
    deps.remember_imports(store)
    assert os.path.join("src", "chain", "c.py") in deps.script_sources(script, package)


@pytest.mark.parametrize(
    "text", ["", "{not json", "[1, 2]", '{"x": 1}', '{"A": 5}', '{"A": [1, 2, [["chain"]]]}']
)
def test_a_damaged_store_is_an_empty_one(checkout, fresh_process, tmp_path, text):
    script, package = checkout
    store = tmp_path / "imports.json"
    store.write_text(text.replace("A", str(package / "a.py")))
    deps.remember_imports(store)
    assert len(deps.script_sources(script, package)) == 3
    deps.save_imports(store)
    fresh_process()
    deps.remember_imports(store)
    assert len(deps.script_sources(script, package)) == 3


def test_a_local_helpers_own_imports_are_code_inputs_too(checkout, fresh_process, tmp_path):
    """A script's local helper (``_logging.py`` beside it) and what the helper imports of
    the package are both inputs: editing either reruns the script's jobs."""
    script, package = checkout
    (tmp_path / "_helper.py").write_text("from chain.c import h\n")
    script.write_text("import _helper\nfrom chain.a import f\n")
    files = deps.script_sources(script, package)
    assert "_helper.py" in files and os.path.join("src", "chain", "c.py") in files
