"""The report: figures, the summary and the article, from the tables. It computes no
physics.

One module per figure (``fig1_setup``, ``fig2_experiment_traces``,
``fig3_simulation_traces``, ``fig4_delay_vs_force``, ``fig5_ssw_vs_force``,
``fig_parity_ssw_vs_N``), with the panels Fig. 2 and 3 share in :mod:`.trace_panels`;
the look of every figure (rc parameters, colours, markers, saving) in :mod:`.style`; the
table look-ups that choose what to draw in :mod:`.picks`. Plot functions take an ``ax``
where they draw one axes, and compute nothing. ``summary.json`` is built in
:mod:`.summary`, ``summary.md`` written in :mod:`.summary_md`; the paper's own numbers
are in :mod:`.paper`, quoted as printed; the article's claims and their verdicts are in
:mod:`.claims`, its numbers as printed in :mod:`.printed` and :mod:`.article`. A new
figure is a new module here, a script in ``workflow/scripts`` and a rule in
``workflow/rules/figures.smk``.
"""
