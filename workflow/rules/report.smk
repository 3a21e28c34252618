# The report: summary.json (the run's numbers beside the paper's, with the sections the
# studies add) and summary.md from it, article.pdf (compiled by the typst package from
# workflow/report/article.typ with the run's numbers and figures), and the run folder:
# plain copies of every file the run shows, checked against the digests stored with
# them, and their SHA256SUMS. Included last: it gathers what the other files publish.


rule summary:
    input:
        **{
            f"{part}__{name}": made(rule, output, **wildcards)
            for part, (_, tables) in SUMMARY_PARTS.items()
            for name, (rule, output, wildcards) in tables.items()
        },
        delay_fits=made("delay_fits", "fits"),
        ssw_fits=made("ssw", "fits"),
        pulses=made("pulses", "table"),
        delays=made("delay_fits", "delays"),
        ssw=made("ssw", "ssw"),
        ssw_speed=made("ssw_speed", "speed"),
        selection=selection_files,
        runs=lambda w: [
            output_of("simulate", "runs", model=m, N=n)
            for m in PLAN.models
            for n in PLAN.chains
        ],
    output:
        json=stored("summary", "summary.json"),
        md=report(
            stored("summary", "summary.md"),
            caption="../report/summary.rst",
            category="Summary",
        ),
        sums=stored("summary", "SHA256SUMS"),
    log:
        stored("summary", "log"),
    benchmark:
        stored("summary", "benchmark.tsv")
    conda:
        ENV
    params:
        run_name=PLAN.run_name,
        material=config["material"],
        radius_m=config["radius_m"],
        conservative_models=list(PLAN.conservative),
        estimator=config["analysis"]["main_estimator"],
        experiment_label=PLAN.experiment.label,
        tolerance=config["experiment"]["tolerance"],
        parts={
            part: [function, list(tables)]
            for part, (function, tables) in SUMMARY_PARTS.items()
        },
        # The studies switched off (summary.md and the article say they did not run).
        studies_not_run=PLAN.studies_not_run,
        # Commit, config hash, installed versions and how they compare with the lock.
        provenance=PLAN.provenance,
    script:
        "../scripts/summary.py"


rule article:
    input:
        # Relative to the working directory: a copied checkout names the same input.
        source=os.path.relpath(CHECKOUT / "workflow" / "report" / "article.typ"),
        summary=made("summary", "json"),
        delays=made("delay_fits", "delays"),
        ssw=made("ssw", "ssw"),
        figures=lambda w: [
            output_of(rule, name, **wildcards)
            for path, (rule, name, wildcards) in RUN_FOLDER.items()
            if path.startswith("figures/") and path.endswith(".pdf")
        ],
    output:
        pdf=stored("article", "article.pdf"),
        sums=stored("article", "SHA256SUMS"),
    log:
        stored("article", "log"),
    benchmark:
        stored("article", "benchmark.tsv")
    conda:
        ENV
    params:
        setup=PLAN.article_setup,
        # A changed commit or configuration rebuilds the article, which states them.
        provenance=PLAN.provenance,
    script:
        "../scripts/article.py"


for path, rule, name in [
    ("summary.json", "summary", "json"),
    ("summary.md", "summary", "md"),
    ("article.pdf", "article", "pdf"),
]:
    publish(path, rule, name)


# One job copies the run's files from the store into the run folder, each checked
# against the digest stored with it, with the logs and benchmarks of every job they
# come from; SHA256SUMS last. On the machine that runs Snakemake: a copy is not worth a
# batch job. Its own log is beside the run folder: it is written after SHA256SUMS.
rule run_folder:
    input:
        lambda w: [
            output_of(rule, name, **wc) for rule, name, wc in RUN_FOLDER.values()
        ],
    output:
        [f"{OUT}/{path}" for path in RUN_FOLDER],
        sums=f"{OUT}/SHA256SUMS",
    log:
        f"results/.logs/{PLAN.run_name}/run_folder.log",
    localrule: True
    conda:
        ENV
    script:
        "../scripts/run_folder.py"
