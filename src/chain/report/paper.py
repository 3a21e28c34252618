"""The paper's own numbers, quoted as printed: never computed, only compared with."""

#: The paper's numbers, as printed (Fig. 4 caption and Eq. 6), us N^(1/6).
PAPER = {"C_exp_us_N16": 45.9, "C_exp_err_us_N16": 0.5, "C_bal_us_N16": 49.74}

#: Relative energy variation the paper's integration keeps to (Sec. II).
PAPER_ENERGY_DRIFT = 1e-9
