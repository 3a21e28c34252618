"""The report: figures, the summary and the article, from the tables. It computes no
physics.

* :mod:`.numbers`: what the run found and what it means, decided once and written to
  ``summary.json`` (the summary, the paper's own numbers, the claims and their
  verdicts, the studies' entries);
* :mod:`.text`: ``summary.md`` and the article, formatted from ``summary.json``: they
  read verdicts and ratios, never decide them;
* :mod:`.figures`: one module per figure, the panels Fig. 2 and 3 share, the table
  look-ups that choose what to draw and the look of every figure. Plot functions take
  an ``ax`` where they draw one axes, and compute nothing;
* :mod:`.printed` (how a number is printed) and :mod:`.naming` (how a series is
  named) serve all three.

Imports run text -> numbers <- figures (``tests/test_layering.py``); where a new figure
or verdict goes: ``docs/architecture.md``. This ``__init__`` imports nothing, so that a
figure's rule depends on its own code only.
"""
