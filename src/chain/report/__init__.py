"""The report: figures and the summary, from the tables. It computes no physics.

Plot functions take an ``ax`` and compute nothing; the paper's own numbers are in
:mod:`.paper`, quoted as printed.
"""
