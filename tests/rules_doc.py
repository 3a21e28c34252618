"""Write docs/rules.md, the rules of the workflow listed from its rule files:

    python tests/rules_doc.py > docs/rules.md

A table per rule file (the Snakefile's rule, then workflow/rules/*.smk in the order the
Snakefile includes them): each rule, the script it runs, its outputs (their paths in
its folder of the store) and what it reads. Read from the files' text, no config
needed: a rule is a line ``rule <name>:`` (or ``localrule``) at the left margin, its
directives the lines indented by four spaces under it, the bodies of ``input:`` and
``output:`` Python arguments (parsed with :mod:`ast`). tests/test_rules_doc.py fails
when docs/rules.md is not what this prints.
"""

from __future__ import annotations

import ast
import os
import re
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RULE = re.compile(r"^(local)?rule (\w+):\s*$")
DIRECTIVE = re.compile(r"^    (\w+):(.*)$")
INCLUDE = re.compile(r'^include:\s*"([^"]+)"', re.M)
#: What another rule's outputs are read through (common.smk).
READERS = ("made", "output_of")
#: Collections of (rule, output, wildcards) that a rule reads every entry of.
COLLECTIONS = {
    "RUN_FOLDER": "the files `publish()`ed",
    "SUMMARY_PARTS": "the tables `summarise()`d",
}

HEADER = """\
# The rules

Every rule of the workflow, by the file it is written in: the script it runs, what it
writes and what it reads. Generated from the rule files by
`python tests/rules_doc.py > docs/rules.md` (tests/test_rules_doc.py fails when this
page is not what that prints); the Snakefile includes the files in this order.

A computing rule writes into its own folder of the result store,
`results/.store/<rule>-<wildcards>-<key>/` (`stored()` in
[common.smk](../workflow/rules/common.smk)): the outputs listed here, its `log`,
`benchmark.tsv` and `SHA256SUMS`. In *reads*, `rule.output` is the output `output` of
another rule (`made()`, `output_of()`), `name()` a function of common.smk, and `PLAN`
the run's plan (`chain.pipeline.plan`). The run folder `results/<run_name>/` holds
copies of what the rule files `publish()`, made by rule `run_folder`.
"""


def rule_files(root: Path = ROOT) -> list[Path]:
    """The Snakefile, then the rule files it includes in its order, then any other."""
    included = [root / path for path in INCLUDE.findall((root / "Snakefile").read_text())]
    others = sorted(set((root / "workflow" / "rules").glob("*.smk")) - set(included))
    return [root / "Snakefile", *included, *others]


def functions(files: list[Path]) -> set[str]:
    """The functions the rule files define (the input functions among them)."""
    return {name for f in files for name in re.findall(r"^def (\w+)\(", f.read_text(), re.M)}


def header_sentence(text: str) -> str:
    """The first sentence of a file's opening comment."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    words = " ".join(lines)
    end = re.search(r"\.(\s|$)", words)
    return words[: end.start() + 1] if end else words


def rules_of(text: str) -> list[tuple[str, bool, dict[str, str]]]:
    """(name, local, directive -> body text) of each rule written in ``text``."""
    found, lines = [], text.splitlines()
    for n, line in enumerate(lines):
        match = RULE.match(line)
        if not match:
            continue
        directives, current = {}, None
        for body in lines[n + 1 :]:
            if body.strip() and not body.startswith(" "):
                break
            if directive := DIRECTIVE.match(body):
                current = directive[1]
                directives[current] = directive[2].strip()
            elif current is not None and not body.lstrip().startswith("#"):
                directives[current] += "\n" + body
        found.append((match[2], bool(match[1]), directives))
    return found


def arguments(body: str) -> list[ast.AST]:
    """The arguments (positional, keyword and ``**`` values) of a directive's body."""
    call = ast.parse(f"f(\n{textwrap.dedent(body)}\n)", mode="eval").body
    return [*call.args, *(keyword.value for keyword in call.keywords)]


def text_of(node: ast.AST) -> str:
    """A path written as a string, an f-string (its fields as ``{...}``), or a ``/``
    of them; else the expression."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(
            part.value if isinstance(part, ast.Constant) else "{" + ast.unparse(part.value) + "}"
            for part in node.values
        )
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
        parts = [text_of(node.left), text_of(node.right)]
        return "/".join(p for p in parts if p != "CHECKOUT")
    return ast.unparse(node)


def outputs(body: str) -> list[str]:
    """The paths of a rule's outputs (in code quotes), its store folder's seal left out."""
    paths = []
    for value in arguments(body):
        stored = [node for node in ast.walk(value) if _called(node) == "stored"]
        if stored:
            path = stored[0].args[1]
            if isinstance(path, ast.Constant | ast.JoinedStr):
                folder = "/" if _called(value) == "directory" else ""
                paths.append(f"`{text_of(path)}{folder}`")
            else:  # a file per item of a mapping
                loop = next(node for node in ast.walk(value) if hasattr(node, "generators"))
                each = ast.unparse(loop.generators[0].iter).removesuffix(".items()")
                paths.append(f"a file per item of `{each}`")
        elif hasattr(value, "generators"):
            path = text_of(value.elt).replace("{OUT}", "results/<run_name>")
            paths.append(f"`{path}` for {' and '.join(_collections(value))}")
        else:
            paths.append(f"`{text_of(value).replace('{OUT}', 'results/<run_name>')}`")
    return [path for path in paths if path != "`SHA256SUMS`"]


def _collections(node: ast.AST) -> list[str]:
    """What a comprehension iterates over, in words where it is a known collection."""
    names = {n.id for g in node.generators for n in ast.walk(g.iter) if isinstance(n, ast.Name)}
    return [COLLECTIONS[name] for name in sorted(names) if name in COLLECTIONS]


def reads(body: str, defined: set[str]) -> list[str]:
    """What a rule's inputs are: other rules' outputs, input functions, plan attributes
    and files, in the order written, each once."""
    found = []
    for value in arguments(body):
        if isinstance(value, ast.Attribute | ast.BinOp):  # a plan's files, a file
            found.append(f"`{text_of(value)}`")
        else:
            found += _sources(value, defined)
    return list(dict.fromkeys(found))


def _sources(node: ast.AST, defined: set[str]) -> list[str]:
    called = _called(node)
    if called in READERS:
        rule, name = node.args[0], node.args[1]
        if isinstance(rule, ast.Constant):
            return [f"`{rule.value}.{text_of(name)}`"]
        return []
    if (isinstance(node, ast.Name) and node.id in defined) or called in defined:
        return [f"`{node.id if isinstance(node, ast.Name) else called}()`"]
    if hasattr(node, "generators") and _collections(node):
        return _collections(node)
    found = []
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.comprehension):
            continue  # what a comprehension iterates over is not read
        found += _sources(child, defined)
    return found


def _called(node: ast.AST) -> str | None:
    """The name of the function ``node`` calls, if it is a call of a plain name."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return node.func.id
    return None


def script_of(body: str, rule_file: Path, root: Path) -> str:
    """The script of a rule, as a link from docs/."""
    path = os.path.normpath(rule_file.parent / ast.literal_eval(body.strip().rstrip(",")))
    relative = Path(path).relative_to(root).as_posix()
    return f"[{Path(path).name}](../{relative})"


def cell(items: list[str]) -> str:
    return "<br>".join(item.replace("|", "\\|") for item in items)


def document(root: Path = ROOT) -> str:
    """docs/rules.md."""
    files = rule_files(root)
    defined = functions(files)
    parts = [HEADER]
    for path in files:
        text = path.read_text()
        rules = rules_of(text)
        if not rules:
            continue
        relative = path.relative_to(root).as_posix()
        parts.append(f"\n## [{relative}](../{relative})\n")
        if path.suffix == ".smk":
            parts.append(f"\n{textwrap.fill(header_sentence(text), 88)}\n")
        parts.append("\n| rule | script | outputs | reads |\n|---|---|---|---|\n")
        for name, local, directives in rules:
            script = script_of(directives["script"], path, root) if "script" in directives else ""
            written = outputs(directives["output"]) if "output" in directives else []
            read = reads(directives["input"], defined) if "input" in directives else []
            rule = f"`{name}`" + (" (local)" if local else "")
            parts.append(f"| {rule} | {script} | {cell(written)} | {cell(read)} |\n")
    return "".join(parts)


if __name__ == "__main__":
    sys.stdout.write(document(Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else ROOT))
