"""How evenly a trace must be sampled: one tolerance for the trace table
(:func:`chain.traces.validate_traces`) and a lab's shot files
(:mod:`chain.apparatus.shot_files`), so that a dataset the check accepts also loads."""

#: Largest deviation of a time step from the nominal one (a shot's median step, or a
#: dataset's ``sampling_interval_s``), as a fraction of it. Generous enough for times
#: written with 6 significant digits.
TIME_STEP_TOLERANCE = 0.01
