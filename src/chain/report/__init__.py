"""The report: figures, the summary and the article, from the tables. It computes no
physics.

Plot functions take an ``ax`` and compute nothing; the paper's own numbers are in
:mod:`.paper`, quoted as printed; the article's claims and their verdicts are in
:mod:`.claims`, its numbers as printed in :mod:`.printed` and :mod:`.article`.
"""
