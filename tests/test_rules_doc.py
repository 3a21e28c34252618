"""docs/rules.md, the rules listed by rule file with their scripts, outputs and inputs,
is what tests/rules_doc.py makes of the rule files."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GENERATOR = ROOT / "tests" / "rules_doc.py"
DOC = ROOT / "docs" / "rules.md"
COMMAND = "python tests/rules_doc.py > docs/rules.md"


def generator():
    """tests/rules_doc.py as a module (whatever pytest's import mode)."""
    spec = importlib.util.spec_from_file_location("rules_doc", GENERATOR)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_docs_rules_md_is_the_rule_files_list():
    result = subprocess.run(
        [sys.executable, str(GENERATOR)],
        cwd=ROOT,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    assert DOC.read_text() == result.stdout, (
        f"docs/rules.md is not what the rule files give: regenerate it with `{COMMAND}`"
    )


def test_every_rule_is_listed_once_with_its_script():
    """Each ``rule``/``localrule`` line of the Snakefile and workflow/rules/*.smk is one
    row, in its file's table; each script linked exists."""
    module = generator()
    files = module.rule_files()
    assert {p.name for p in files} >= {p.name for p in (ROOT / "workflow/rules").glob("*.smk")}
    doc = module.document()
    sections = re.split(r"^## ", doc, flags=re.M)[1:]
    for path in files:
        written = re.findall(r"^(?:local)?rule (\w+):", path.read_text(), re.M)
        relative = path.relative_to(ROOT).as_posix()
        section = next((s for s in sections if s.startswith(f"[{relative}]")), "")
        listed = re.findall(r"^\| `(\w+)`", section, re.M)
        assert listed == written, f"{relative}: rules {written}, listed {listed}"
    for link in re.findall(r"\]\(\.\./(workflow/scripts/[^)]+)\)", doc):
        assert (ROOT / link).is_file(), link
