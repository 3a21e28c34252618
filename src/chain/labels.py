"""Names a person reads in figures, tables and the summary, each defined once.

The virtual experiment is a model of the apparatus, never data: every figure, table
row and summary line that shows it carries :data:`VIRTUAL_LABEL`.
"""

#: Series name (``model`` column) of the virtual experiment's rows.
VIRTUAL_SERIES = "virtual"

#: Label of the virtual experiment's rows in figures and summary (not data).
VIRTUAL_LABEL = "virtual experiment (model)"

#: Reason given in experiment/selection.csv for a shot left out because a channel is
#: dead or saturated (``experiment.bad_channels: skip``).
SKIPPED_REASON = "skipped (experiment.bad_channels: skip)"

#: Mechanism name (``tables/ssw_mechanisms.csv``) of the LAMMPS friction/rotation rows.
FRICTION_MECHANISM = "rotation + friction (LAMMPS)"

#: Mechanism name of the LAMMPS rows with a viscous inter-bead force instead of
#: Kuwabara-Kono (on the frictionless track).
VISCOUS_MECHANISM = "viscous inter-bead term (LAMMPS)"

#: Mechanism name of the candidates' reference row.
REFERENCE_MECHANISM = "reference (virtual experiment as configured)"
