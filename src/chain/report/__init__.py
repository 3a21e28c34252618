"""The report: figures, the summary and the article, from the tables. It computes no
physics.

Three subpackages, by what they make, and two modules all three share:

* :mod:`.numbers`: what the run found and what it means, decided once and written to
  ``summary.json``: the summary itself (:mod:`.numbers.summary`), the paper's own
  numbers (:mod:`.numbers.paper`, quoted as printed), the claims with their verdicts
  against the tolerance table (:mod:`.numbers.claims`, :mod:`.numbers.ssw_claims`,
  :mod:`.numbers.claim_rows`), the ablation and C-spread
  entries (:mod:`.numbers.spread`) and the mechanism study's verdict
  (:mod:`.numbers.mechanisms`).
* :mod:`.text`: ``summary.md`` (:mod:`.text.markdown`) and the article
  (:mod:`.text.article` and its tables and figure texts), formatted from
  ``summary.json``: they read verdicts and ratios, never decide them.
* :mod:`.figures`: one module per figure (``fig*``), the panels Fig. 2 and 3 share
  (:mod:`.figures.trace_panels`), the table look-ups that choose what to draw
  (:mod:`.figures.picks`) and the look of every figure (:mod:`.figures.style`). Plot
  functions take an ``ax`` where they draw one axes, and compute nothing.
* :mod:`.printed` (how a number is printed) and :mod:`.naming` (how a series is
  named) serve all three.

Imports run: text -> numbers -> printed, naming; figures -> numbers.paper, printed,
naming (``tests/test_layering.py``). A new figure is a new module in ``figures/``, a
script in ``workflow/scripts`` and a rule in ``workflow/rules/figures.smk``; a new
verdict goes into ``numbers/`` and reaches the text through ``summary.json``. This
``__init__`` imports nothing, so that a figure's rule depends on its own code only.
"""
