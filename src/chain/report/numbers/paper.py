"""The paper's own numbers, quoted as printed: never computed, only compared with."""

from chain.physics.materials import STEEL_100C6

#: The paper's numbers, as printed (Fig. 4 caption and Eq. 6), us N^(1/6).
PAPER = {"C_exp_us_N16": 45.9, "C_exp_err_us_N16": 0.5, "C_bal_us_N16": 49.74}

#: Relative energy variation the paper's integration keeps to (Sec. II).
PAPER_ENERGY_DRIFT = 1e-9

#: The paper's beads (Sec. II): 100C6 steel, R = 13 mm. Its numbers are comparable with
#: a run's only for these beads.
PAPER_BEADS = {"material": STEEL_100C6.name, "radius_m": 13e-3}
