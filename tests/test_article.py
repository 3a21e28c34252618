"""article.pdf: the typst source compiled with a run's numbers and figures, read back.

The figures here are textless PDFs of distinct sizes, so every number found in the PDF's
text comes from the article's own text, and each figure can be told from the others by
its size. The summary is the paper run's (tests/data/article/summary.json).

Numbers are looked for as the article prints them: C, the exponents and the SSW slopes
as value ± error by chain.report.printed.plus_minus (tests/test_printed.py tests that
rule), C_bal with 2 decimals, the energy drift with 2 significant digits
(mantissa × 10^exponent). The layout of the built PDF is checked word by word
(tests/pdf_layout.py).
"""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pypdf
import pytest
from matplotlib.figure import Figure

from chain.pipeline.provenance.headline import headline_numbers
from chain.report.numbers.claim_rows import NOT_COMPUTED, TOLERANCES
from chain.report.numbers.claims import claims, with_claims
from chain.report.numbers.summary import decisions
from chain.report.printed import E_NOTATION, plus_minus
from chain.report.text.article import CAPTIONS, article_numbers, compile_article
from chain.report.text.article_figures import PARAGRAPHS
from chain.report.text.article_tables import ablation_tables, c_spread_tables

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "workflow" / "report" / "article.typ"
SUMMARY = json.loads((ROOT / "tests" / "data" / "article" / "summary.json").read_text())

#: Figures of the fixture: every captioned one, and one the article does not know.
FIGURE_NAMES = [*CAPTIONS, "fig_extra_whatif"]

#: The findings other stages add to summary.json, in the shape the article reads.
FINDINGS = {
    "ssw_resolved": [
        {"source": "simulation", "model": "elastic", "N": 26, "sensor": "S2",
         "resolved": True, "n_resolved": 24, "n_total": 24},
        {"source": "simulation", "model": "elastic", "N": 25, "sensor": "S2",
         "resolved": False, "n_resolved": 0, "n_total": 24},
    ],
    "ssw_separation": [
        {"model": "elastic", "N": 26, "wave": "LSTW", "first_separated_contact": 7,
         "distance_beads": 6.5, "speed_ratio": 1.0123},
    ],
    "ssw_parity_ratio": [{"source": "simulation", "model": "elastic", "ratio": 3.21}],
    "ssw_far_field": [
        {"source": "simulation", "model": "elastic", "even_N": 120, "odd_N": 121,
         "even": 0.0299, "even_err": 1e-5, "odd": 0.00848, "odd_err": 1e-6,
         "ratio": 3.526, "ratio_err": 0.001},
    ],
    "ablation": {
        "verdict": "Synthetic verdict: the striker's trailing train steepens the exponent.",
        "rows": [{"variant": "baseline", "N": 25, "C": 44.3, "C_stderr": 0.6,
                  "exponent": -0.214, "exponent_stderr": 0.011}],
    },
    "c_spread": {"headline_choice": "fit_full, eta = paper, S1/S2", "min_us_N16": 31.41,
                 "max_us_N16": 46.78, "rows": [{"choice": "fit_rise", "C": 33.77}]},
}  # fmt: skip


def textless_figure(path: Path, width_in: float) -> None:
    """A PDF figure with a curve and no text, ``width_in`` inches wide."""
    fig = Figure(figsize=(width_in, 3.0))  # no pyplot: no backend, no global state
    ax = fig.add_axes((0, 0, 1, 1))
    ax.plot(np.linspace(0, 1, 50), np.sin(np.linspace(0, 6, 50)))
    ax.set_axis_off()
    fig.savefig(path, metadata={"CreationDate": None})


@pytest.fixture(scope="module")
def figures(tmp_path_factory) -> dict[str, Path]:
    """name -> textless PDF; widths 4.0, 4.25, 4.5, ... inches tell them apart."""
    folder = tmp_path_factory.mktemp("figures")
    paths = {}
    for index, name in enumerate(FIGURE_NAMES):
        paths[name] = folder / f"{name}.pdf"
        textless_figure(paths[name], 4.0 + 0.25 * index)
    return paths


def decided(summary, delays=None, ssw=None) -> dict:
    """The fixture's summary as the summary step writes it: with its decisions and the
    claim table (the article only formats them)."""
    return with_claims({**summary, **decisions(summary)}, delays, ssw)


def build(folder: Path, figures: dict, summary=SUMMARY, delays=None, ssw=None) -> Path:
    numbers = article_numbers(decided(summary, delays, ssw), setup=None)
    output = folder / "article.pdf"
    compile_article(SOURCE, numbers, list(figures.values()), output)
    return output


def raw_text(path: Path) -> str:
    """All text of the PDF as pypdf extracts it, hyphenation at line ends undone."""
    reader = pypdf.PdfReader(path)
    return re.sub(r"-\n", "", "\n".join(page.extract_text() for page in reader.pages))


def pdf_text(path: Path) -> str:
    """All text of the PDF, whitespace removed, minus signs ASCII."""
    return re.sub(r"\s+", "", raw_text(path)).replace("\u2212", "-")


#: The standard error of each headline number that has one, by headline name.
ERRORS = {
    **{
        f"{kind}/{r['source']}/{r['model']}/N={r['N']}/{r['estimator']}": r[error]
        for r in SUMMARY["delay_fits"]
        for kind, error in (("C_us_N16", "C_stderr_us_N16"), ("exponent", "exponent_stderr"))
    },
    **{
        f"ssw_slope/{r['source']}/{r['model']}/N={r['N']}/{r.get('method', 'residual')}": r[
            "slope_stderr"
        ]
        for r in SUMMARY["ssw_fits"]
    },
}


def printed(name: str, value: float) -> str:
    """A headline number as the article prints it (module docstring), spaces removed
    and minus signs ASCII as in :func:`pdf_text`."""
    if name in ERRORS:
        text = plus_minus(value, ERRORS[name])
        return re.sub(r"\s+", "", text).replace("\u2212", "-").replace("10^", "10")
    if name.startswith("C_bal"):
        return f"{value:.2f}"
    if name == "max_energy_drift":
        mantissa, exponent = f"{value:.1e}".split("e")
        return f"{mantissa}×10{int(exponent)}"
    raise AssertionError(f"no printing rule for {name}")


@pytest.fixture(scope="module")
def article(tmp_path_factory, figures) -> Path:
    return build(tmp_path_factory.mktemp("article"), figures)


def test_every_headline_number_is_printed(article):
    text = pdf_text(article)
    numbers = headline_numbers(SUMMARY)
    missing = {
        name: printed(name, value)
        for name, value in numbers.items()
        if printed(name, value) not in text
    }
    assert len(numbers) > 50
    assert not missing, missing
    # The paper's own values, quoted.
    paper = SUMMARY["paper"]
    assert f"{paper['C_exp_us_N16']:.1f}±{paper['C_exp_err_us_N16']:.1f}" in text
    assert f"{paper['C_bal_us_N16']:.2f}" in text


def test_every_figure_is_embedded_as_a_vector_form(article, figures):
    reader = pypdf.PdfReader(article)
    widths = set()
    for page in reader.pages:
        xobjects = page.get("/Resources", {}).get("/XObject", {})
        for reference in xobjects.values():
            xobject = reference.get_object()
            assert xobject["/Subtype"] == "/Form", "figures must stay vector (PDF forms)"
            box = [float(v) for v in xobject["/BBox"]]
            widths.add(round(box[2] - box[0]))
    # matplotlib writes 72 points per inch: one form per figure, each of its own width.
    expected = {round(72 * (4.0 + 0.25 * i)) for i in range(len(FIGURE_NAMES))}
    assert widths == expected


def test_the_same_inputs_give_the_same_bytes(article, figures, tmp_path):
    again = build(tmp_path, figures)
    assert again.read_bytes() == article.read_bytes()


def test_absent_findings_say_not_computed(article):
    text = pdf_text(article)
    phrase = NOT_COMPUTED.replace(" ", "")
    # SSW resolved, separation, parity ratio, C spread, ablation (+ the claim rows).
    assert text.count(phrase) >= 5
    placeholders = re.findall(r"\b(None|nan|NaN|n/a|TODO|XX+)\b", raw_text(article))
    assert not placeholders


def test_findings_render_when_present(tmp_path, figures):
    summary = {**copy.deepcopy(SUMMARY), **FINDINGS}
    text = pdf_text(build(tmp_path, figures, summary))
    assert FINDINGS["ablation"]["verdict"].replace(" ", "") in text
    assert "from31.41to46.78" in text  # the C spread
    assert "1of2sensorseries" in text  # SSW resolved
    assert "1.012" in text and "3.21" in text  # speed ratio, parity ratio
    assert "3.526" in text  # far-field even / odd
    # The experiment's exponent is now explained by the ablation, in the claims too.
    assert text.count(FINDINGS["ablation"]["verdict"].replace(" ", "")) >= 2
    assert "Whetherthe SSWisresolvedateachsensor".replace(" ", "") not in text
    assert "Itscause,switchingthemodel" not in text


def with_exponent(summary, model, exponent):
    out = copy.deepcopy(summary)
    for row in out["delay_fits"]:
        if row["model"] == model and row["N"] == "pooled" and row["estimator"] == "fit_full":
            row["exponent"] = exponent
    return out


def verdicts(summary, **tables) -> dict[str, str]:
    return {row["claim"]: row["agrees"] for row in claims(summary, **tables)}


def test_verdicts_follow_the_numbers_and_tolerances():
    table = verdicts(SUMMARY)
    assert table["|Δ| ∝ F_m^(−1/6), simulation, elastic"] == "yes"
    assert table["|Δ| ∝ F_m^(−1/6), virtual experiment (model)"] == "no"
    assert table["Eq. 6 evaluated for the paper's beads"] == "yes"  # 49.75 vs 49.74
    assert table["Eq. 6 is the ballistic collision-time difference"] == "no"  # 37.74
    assert table["Viscoelastic dissipation does not change Δ"] == "no"  # C ratio 1.081
    # The virtual experiment (a model) has the SSW of the viscoelastic simulation, less:
    # not reproduced (the claim's row says so, with the ratio).
    assert table["Simulated SSW much smaller than measured"] == "no"
    # Just inside and just outside the stated tolerance on the exponent.
    tolerance = TOLERANCES["delay_exponent"]
    inside = with_exponent(SUMMARY, "virtual", -1 / 6 - 0.9 * tolerance)
    outside = with_exponent(SUMMARY, "elastic", -1 / 6 + 1.1 * tolerance)
    assert verdicts(inside)["|Δ| ∝ F_m^(−1/6), virtual experiment (model)"] == "yes"
    assert verdicts(outside)["|Δ| ∝ F_m^(−1/6), simulation, elastic"] == "no"


def test_sign_and_ssw_claims_come_from_the_tables():
    f_m = np.geomspace(10, 1000, 8)
    delays = pd.DataFrame(
        {
            "source": "simulation", "model": "elastic", "estimator": "fit_full",
            "F_m_N": f_m, "delay_us": -40 * f_m ** (-1 / 6), "ok": True,
        }
    )  # fmt: skip
    ssw = pd.DataFrame(
        {
            "source": "simulation", "model": "elastic", "N": 26, "method": "residual",
            "F_m_N": f_m, "ssw_N": 0.05 * f_m, "ok": True,
        }
    )  # fmt: skip
    table = verdicts(SUMMARY, delays=delays, ssw=ssw)
    assert table["Crossed waves come out early (a phase shift)"] == "yes"
    assert table["SSW amplitude ∝ F_m (simulation, elastic)"] == "yes"
    delays.loc[0, "delay_us"] = 1.0  # one crossed wave late
    ssw["ssw_N"] = 0.05 * f_m**1.2  # not proportional
    table = verdicts(SUMMARY, delays=delays, ssw=ssw)
    assert table["Crossed waves come out early (a phase shift)"] == "no"
    assert table["SSW amplitude ∝ F_m (simulation, elastic)"] == "no"


def test_a_run_without_experiment_says_so(tmp_path, figures):
    summary = copy.deepcopy(SUMMARY)
    for key in ("delay_fits", "ssw_fits"):
        summary[key] = [r for r in summary[key] if r["source"] == "simulation"]
    summary.update(experiment_label="experiment", selection=[], experiment_tolerance=None)
    numbers = article_numbers(decided(summary), setup={"source": "none"})
    shown = {k: v for k, v in figures.items() if k != "fig2_experiment_traces"}
    compile_article(SOURCE, numbers, list(shown.values()), tmp_path / "article.pdf")
    text = pdf_text(tmp_path / "article.pdf")
    assert "Thisrunhasnoexperimentside." in text
    assert "Thisrunhasnoexperimentseries." in text
    assert "virtualexperiment(model)" not in text


def test_the_layout_has_no_word_off_the_page_in_the_margin_or_overprinted(tmp_path, figures):
    """With every finding present (the long tables), as the paper run builds it."""
    from pdf_layout import layout_problems

    summary = {**copy.deepcopy(SUMMARY), **FINDINGS}
    assert layout_problems(build(tmp_path, figures, summary)) == []


PAPER_ARTICLE = ROOT / "results" / "paper" / "article.pdf"


@pytest.mark.skipif(not PAPER_ARTICLE.exists(), reason="the paper run has not been built")
def test_the_paper_runs_article_has_a_clean_layout():
    """The article `snakemake --cores 2` built in this checkout, real figures included."""
    from pdf_layout import layout_problems

    assert layout_problems(PAPER_ARTICLE) == []


def test_the_layout_check_finds_what_it_is_for(tmp_path):
    """A word off the page, one in the bottom margin and two overprinted words are found
    and named, a superscript on its base and the page number are not."""
    from pdf_layout import layout_problems

    source = tmp_path / "bad.typ"
    source.write_text(
        '#set page(paper: "a4", margin: (x: 2.2cm, y: 2.4cm), numbering: "1")\n'
        "Plain text with x#super[2] and #place(dx: -3cm)[offpage]\n"
        "#place(dx: 5cm, dy: 5cm)[Overprinted] #place(dx: 5.1cm, dy: 5cm)[Overprinted]\n"
        "#place(bottom, dy: 1.5cm)[footerword]\n"
    )
    import typst

    pdf = tmp_path / "bad.pdf"
    pdf.write_bytes(typst.compile(str(source), ignore_system_fonts=True))
    problems = "\n".join(layout_problems(pdf))
    assert "page 1: words outside the page: ['offpage']" in problems
    assert "page 1: words in the bottom margin: ['footerword']" in problems
    assert "page 1: overprinted words" in problems and "OOvveerrpprriinntteedd" in problems
    assert "'x'/'2'" not in problems and "'1'" not in problems


def test_every_figure_sits_under_a_paragraph_that_discusses_it(article):
    """No empty section: a figure the text does not know gets a section of its own with
    a paragraph naming it; the supplementary figures each get their paragraph."""
    text = raw_text(article)
    assert "Further figures" not in text
    assert "Supplementary figures" in text
    flat = re.sub(r"\s+", " ", text)
    for name in ("fig_c_sensitivity", "ssw_spacetime", "fig_parity_ssw_vs_N", "fig_c_vs_N"):
        paragraph = PARAGRAPHS[name](SUMMARY)
        assert re.sub(r"\s+", " ", paragraph[:40]) in flat, name
    assert "is a figure of this run that the article's text does not discuss" in flat


def test_provenance_is_printed(tmp_path, figures):
    provenance = {
        "commit": "0123456789ab", "date": "2026-01-02", "dirty": True,
        "config_hash": "fedcba987654", "versions": {"numpy": "9.9.9"},
    }  # fmt: skip
    numbers = article_numbers(decided(SUMMARY), provenance=provenance)
    compile_article(SOURCE, numbers, list(figures.values()), tmp_path / "article.pdf")
    text = re.sub(r"\s+", " ", raw_text(tmp_path / "article.pdf"))
    assert "0123456789ab with uncommitted changes" in text
    assert "2026-01-02" in text and "fedcba987654" in text and "numpy 9.9.9" in text


def test_long_tables_keep_pooled_rows_in_the_body_and_every_row_in_the_appendix():
    rows = [
        {"choice": "eta_us", "value": v, "N": n, "C": c, "C_stderr": 0.0523,
         "exponent": -0.1516, "exponent_stderr": 0.0033, "n_points": 24, "headline": v == 0.58,
         "note": "no usable delay on N = 26" if n == "pooled" and v == 1.16 else None}
        for v in (0.0, 0.58, 1.16) for n, c in ((25, 44.6), (26, None), ("pooled", 43.21))
    ]  # fmt: skip
    tables = c_spread_tables(rows)
    body, appendix = tables["body"], tables["appendix"]
    assert len(body["rows"]) == 3 and len(appendix["rows"]) == 9
    assert all(len(r) == len(body["columns"]) for r in body["rows"])
    assert "C (µs N^1/6)" in body["columns"]  # the unit in the header
    assert body["rows"][0][1] == "43.21 ± 0.05"  # one rule: chain.report.printed
    assert body["rows"][1][0] == "η = 0.58 µs (headline)"
    assert body["rows"][2][0].endswith("(no usable delay on N = 26)")
    assert appendix["rows"][1][2] == "—"  # a chain without a fit, not "n/a" or "nan"
    ablation = ablation_tables(
        [{"variant": "no_imperfections", "N": "pooled", "C": 42.6, "C_stderr": 0.15,
          "exponent": -0.154, "exponent_stderr": 0.005, "n_points": 96,
          "overrides": "noise_N=0.0; adc_bits=None"}]
    )  # fmt: skip
    assert ablation["body"]["rows"][0][:2] == ["no imperfections", "noise_N = 0.0; adc_bits = None"]
    assert c_spread_tables([]) is None and ablation_tables(None) is None


def ssw_claim(summary, name) -> dict:
    return next(row for row in claims(summary) if row["claim"] == name)


def test_ssw_parity_and_experiment_claims_carry_their_numbers():
    """Even > odd is decided by the ratios and their errors, never "not testable" when a
    ratio exists; the virtual experiment (a model) is compared with the simulation."""
    summary = copy.deepcopy(SUMMARY)
    summary["ssw_far_field"] = copy.deepcopy(FINDINGS["ssw_far_field"])
    parity = ssw_claim(summary, "SSW larger in even chains")
    assert parity["agrees"] == "yes" and "3.526" in parity["ours"]
    # The odd chain larger far from the collision point: refuted.
    summary["ssw_far_field"][0].update(ratio=0.8, ratio_err=0.01)
    assert ssw_claim(summary, "SSW larger in even chains")["agrees"] == "no"
    # Everything within 2 errors of 1: a number, so "no" (not shown), not "not testable".
    summary["ssw_far_field"] = []
    for row in summary["ssw_fits"]:
        row["slope_stderr"] = row["slope"]
    parity = ssw_claim(summary, "SSW larger in even chains")
    assert parity["agrees"] == "no" and parity["why"].startswith("not shown")
    # No fits and no long chains: nothing to form a ratio from.
    summary["ssw_fits"] = []
    assert ssw_claim(summary, "SSW larger in even chains")["agrees"] == "not testable"
    experiment = ssw_claim(SUMMARY, "Simulated SSW much smaller than measured")
    # Fixture: virtual 0.0376 / viscoelastic 0.0417 at N = 25.
    assert experiment["agrees"] == "no" and "0.90" in experiment["ours"]
    assert experiment["why"].startswith("not reproduced by the model; see the mechanism study")


def test_the_ssw_tables_are_written_for_reading():
    """Series named as the article names them, counts as "k of n", value ± error."""
    from chain.report.text.article_ssw_tables import (
        far_field_table,
        parity_table,
        resolution_table,
        separation_table,
    )

    def label(source, model):
        return f"{source}, {model}"

    resolved = resolution_table(FINDINGS["ssw_resolved"], label)
    assert resolved["columns"] == ["Series", "N", "S1 (RSTW)", "S2 (LSTW)"]
    assert resolved["rows"][0] == ["simulation, elastic", "26", "—", "24 of 24"]
    far = far_field_table(FINDINGS["ssw_far_field"], label)
    assert far["rows"][0][1:] == ["N = 120 / 121", "2.9900 ± 0.0010", "0.84800 ± 0.00010",
                                  "3.5260 ± 0.0010"]  # fmt: skip
    parity = parity_table([{"source": "experiment", "model": "virtual", "ratio": 1.93,
                            "ratio_err": 2.046}], label)  # fmt: skip
    assert parity["rows"] == [["experiment, virtual", "1.9 ± 2.0"]]
    separation = separation_table(FINDINGS["ssw_separation"], label)
    assert separation["rows"][0][4:] == ["7", "6.5", "1.012"]
    assert all(table(None, label) is None for table in
               (resolution_table, separation_table, parity_table, far_field_table))  # fmt: skip


#: A mechanism study whose numbers and setting names {:g} writes in e-notation.
SMALL_NUMBERS = {
    "max_energy_drift": 5.5e-10,
    "ssw_mechanisms": {
        "verdict": "Of the other candidates, gaps between beads (gap_mean_m=1e-07) comes "
        "closest.",
        "rows": [{"mechanism": "gaps between beads", "setting": "gap_mean_m=1e-07",
                  "N": 25, "ssw_over_Fm": 0.0246, "ratio_to_frictionless": 1.29}],
        "lammps_check": [{"N": 25, "model": "elastic", "C_kernel": 41.43, "C_lammps": 41.43,
                          "rel_diff_C": 7.121e-08, "max_trace_diff_over_Fm": 2.62e-07}],
        "friction_C": [],
    },
}  # fmt: skip


def test_no_raw_e_notation_in_the_article(tmp_path, figures):
    """The article writes 5.5 × 10⁻¹⁰, never 5.5e-10: not in its typst
    source, not in the strings it is given, not in the text of the PDF."""
    assert not E_NOTATION.findall(SOURCE.read_text())
    summary = {**copy.deepcopy(SUMMARY), **FINDINGS, **SMALL_NUMBERS}
    numbers = article_numbers(decided(summary))
    strings = json.dumps(numbers, ensure_ascii=False)
    assert not E_NOTATION.findall(strings), E_NOTATION.findall(strings)
    text = raw_text(build(tmp_path, figures, summary=summary))
    assert not E_NOTATION.findall(text), E_NOTATION.findall(text)
    assert "5.5×10" in re.sub(r"\s+", "", text)  # the drift, with its power of ten


def test_the_why_not_of_the_simulated_c_quotes_the_mechanism_study():
    """With the mechanism study, the claim that Eq. 1 misses the measured Δ says what
    friction does to C; without it, the paper's explanation."""
    name = "Simulations of Eq. 1 close to the measured Δ (simulation, viscoelastic)"
    study = {
        "verdict": "",
        "rows": [],
        "lammps_check": [],
        "friction_C": [
            {"N": 25, "setting": "mu_t=0.3, mu_b=0", "C_frictionless": 44.16, "C": 49.81},
            {"N": 25, "setting": "mu_t=0.3, mu_b=0.3", "C_frictionless": 44.16, "C": 45.08},
        ],
    }
    far = with_exponent(SUMMARY, "viscoelastic", -0.1)
    for row in far["delay_fits"]:
        if row["model"] == "viscoelastic" and row["N"] == "pooled":
            row["C_us_N16"] = 60.0  # far from C_exp: the why-not is printed
    plain = {row["claim"]: row["why"] for row in claims(far)}
    assert plain[name] == "no track friction or bead rotation modelled (the paper's explanation)"
    quoted = {row["claim"]: row["why"] for row in claims({**far, "ssw_mechanisms": study})}
    assert "mechanism study models both" in quoted[name]
    assert "N = 25: C 44.2 -> 45.1-49.8 µs N^(1/6)" in quoted[name]


def test_studies_switched_off_are_said_not_run(tmp_path, figures):
    """A run whose config switches studies off (summary ``studies_not_run``) says so
    where each study's finding would be, naming the key; none of them is made up."""
    summary = {**copy.deepcopy(SUMMARY), "studies_not_run": ["ablation", "c_sensitivity"]}
    numbers = article_numbers(decided(summary), setup=None)
    assert numbers["absent"] == {
        "ablation": "not run in this run (config studies.ablation: false)",
        "c_sensitivity": "not run in this run (config studies.c_sensitivity: false)",
        "mechanisms": NOT_COMPUTED,
    }
    shown = {k: v for k, v in figures.items() if k != "fig_c_sensitivity"}
    compile_article(SOURCE, numbers, list(shown.values()), tmp_path / "article.pdf")
    text = pdf_text(tmp_path / "article.pdf")
    for study in ("ablation", "c_sensitivity"):
        assert f"notruninthisrun(configstudies.{study}:false)" in text, study
    assert "Themechanismstudy:" + NOT_COMPUTED.replace(" ", "") in text
