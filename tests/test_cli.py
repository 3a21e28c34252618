"""The `hertzchain` command: simulate writes a valid trace file, analyse fits it,
theory prints the closed forms, bad input exits 2 with a message naming the parameter."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from chain import read_traces
from chain.cli import main

#: The paper's C_bal (Eq. 6) recomputed from the 100C6 steel values, us N^(1/6).
PAPER_C_BAL_US = 49.747


def test_help_explains_the_commands():
    """`hertzchain --help` lists every command (run as the installed console script)."""
    completed = subprocess.run(
        [sys.executable, "-m", "chain.cli", "--help"], capture_output=True, text=True, check=True
    )
    for command in ("simulate", "analyse", "theory", "check"):
        assert command in completed.stdout


def test_simulate_writes_a_trace_file_that_analyse_reads(tmp_path, capsys):
    """A collision at 0.3 m/s in N = 12: both sensors see the incident and crossed waves."""
    output = tmp_path / "traces.csv"
    status = main(
        [
            "simulate",
            "-N",
            "12",
            "--speed",
            "0.3",
            "--sensors",
            "4",
            "9",
            "--duration",
            "1e-3",
            "-o",
            str(output),
        ]
    )
    assert status == 0
    traces = read_traces(output)
    assert list(traces.columns[-2:]) == ["force_bead4_N", "force_bead9_N"]
    assert set(traces["kind"]) == {"collision"}
    # 0.3 m/s launches a ~235 N wave (F_m ~ 1 kN (V0 / 1 m/s)^(6/5)); the crossing adds.
    assert 200 < traces["force_bead4_N"].max() < 400
    capsys.readouterr()
    assert main(["analyse", str(output)]) == 0
    rows = capsys.readouterr().out.strip().splitlines()
    header = rows[0].split(",")
    assert "F_m_N" in header and "role" in header
    ok = [row for row in rows[1:] if row.split(",")[header.index("ok")] == "True"]
    assert len(ok) == 4  # two sensors x (incident, crossed)


def test_reference_launch_moves_one_wave(tmp_path):
    """--kind reference launches bead 1 only: the far end stays quiet until the wave arrives."""
    output = tmp_path / "reference.csv"
    assert (
        main(
            [
                "simulate",
                "-N",
                "10",
                "--speed",
                "0.1",
                "--kind",
                "reference",
                "--sensors",
                "2",
                "9",
                "--duration",
                "8e-4",
                "-o",
                str(output),
            ]
        )
        == 0
    )
    traces = read_traces(output)
    assert np.all(traces["v0_right_m_s"] == 0.0)
    first = traces["t_s"][traces["force_bead2_N"].idxmax()]
    last = traces["t_s"][traces["force_bead9_N"].idxmax()]
    assert last > first


def test_theory_prints_the_closed_forms(capsys):
    """`hertzchain theory` gives the paper's C_bal and the smaller exact-Hertz value."""
    assert main(["theory"]) == 0
    values = json.loads(capsys.readouterr().out)
    assert values["C_bal_paper_us_N16"] == pytest.approx(PAPER_C_BAL_US, abs=1e-3)
    assert values["C_bal_exact_us_N16"] < values["C_bal_paper_us_N16"]


@pytest.mark.parametrize(
    ("arguments", "fragment"),
    [
        (["simulate", "-N", "1", "--speed", "0.1", "-o", "x.csv"], "n_beads"),
        (["simulate", "-N", "5", "--speed", "-0.1", "-o", "x.csv"], "v_left"),
        (["simulate", "-N", "5", "--speed", "0.1", "--sensors", "7", "-o", "x.csv"], "7"),
        (["simulate", "-N", "5", "--speed", "0.1", "--duration", "0", "-o", "x.csv"], "duration"),
        (["analyse", "missing.csv"], "missing.csv"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(arguments, fragment, tmp_path, monkeypatch, capsys):
    """Bad input: exit status 2, one line on stderr that names the parameter, no file."""
    monkeypatch.chdir(tmp_path)
    assert main(arguments) == 2
    error = capsys.readouterr().err
    assert "error" in error and fragment in error
    assert not (tmp_path / "x.csv").exists()


def test_check_config_names_file_and_line_of_an_overlay_that_is_not_yaml(tmp_path, capsys):
    # The case Snakemake reports as "Config file is not valid JSON or YAML" only.
    good = tmp_path / "good.yaml"
    good.write_text("run_name: ok\nlaunch:\n  count: 4\n")
    broken = tmp_path / "broken.yaml"
    broken.write_text("run_name: x\nlaunch:\n  count: 4\n\tv0_min_m_s: 0.1\n")
    repeated = tmp_path / "repeated.yaml"
    repeated.write_text("run_name: a\nrun_name: b\n")

    assert main(["check-config", str(good)]) == 0
    assert "good.yaml: valid YAML" in capsys.readouterr().out
    assert main(["check-config", str(good), str(broken), str(repeated)]) == 1
    errors = capsys.readouterr().err.splitlines()
    assert len(errors) == 2
    assert errors[0].startswith(f"{broken} line 4, column 1: not valid YAML")
    assert errors[1].startswith(f"{repeated} line 2")
    assert "run_name" in errors[1]
