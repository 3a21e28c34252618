# The reproduction as an article: results/<run_name>/article.pdf, compiled by the typst
# package from workflow/report/article.typ with the run's numbers and figures.
# The source is named relative to the working directory, as the code inputs are.

import os

ARTICLE_SOURCE = os.path.relpath(
    Path(workflow.basedir) / "workflow" / "report" / "article.typ", Path.cwd()
)


rule article:
    input:
        source=ARTICLE_SOURCE,
        summary=f"{OUT}/summary.json",
        delays=f"{TABLES}/delays.csv",
        ssw=f"{TABLES}/ssw.csv",
        figures=[figure(name)[0] for name in PLAN.figure_names()],
        lib=code("article"),
    output:
        f"{OUT}/article.pdf",
    log:
        f"{LOGS}/article.log",
    benchmark:
        f"{BENCH}/article.tsv"
    conda:
        ENV
    params:
        setup={
            "chains": config["chains"],
            "models": config["models"],
            "launch": config["launch"],
            "source": config["experiment"]["source"],
            "virtual": config["experiment"]["virtual"],
            "striker_radius_m": config["setup"]["striker_radius_m"],
            "tolerance": config["experiment"]["tolerance"],
        },
        # Commit, commit date, config hash and versions: a changed commit or
        # configuration rebuilds the article, which states them.
        provenance=PROVENANCE,
    script:
        "../scripts/article.py"
