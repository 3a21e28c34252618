"""The `hertzchain` command: simulate writes a valid trace file, analyse fits it,
theory prints the closed forms, bad input exits 2 with a message naming the option typed."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest

from chain import read_traces
from chain.cli import in_option_words, main

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


SIM = ["simulate", "-N", "5", "--speed", "0.1", "--duration", "2e-4", "-o", "x.csv"]


def _with(*changes: str) -> list[str]:
    """SIM with options changed or added: ``_with("--speed", "-0.3")``."""
    arguments = list(SIM)
    for option, value in zip(changes[::2], changes[1::2]):
        if option in arguments:
            arguments[arguments.index(option) + 1] = value
        else:
            arguments[1:1] = [option, *value.split()]
    return arguments


@pytest.mark.parametrize(
    ("arguments", "option", "library_name"),
    [
        # the library's check speaks of its parameter, the message of the option
        (_with("-N", "1"), "-N must be an integer >= 2, got 1", "n_beads"),
        (_with("--speed", "-0.3"), "--speed must be finite and >= 0 m/s, got -0.3", "v_left"),
        (_with("--speed", "nan"), "--speed must be finite", "v_left"),
        (_with("--speed", "0"), "--speed must be > 0 m/s", "v_right"),
        (_with("--speed", "0", "--kind", "reference"), "--speed must be > 0 m/s", "v_right"),
        (_with("--duration", "0"), "--duration must be a positive", "duration"),
        (_with("--dt", "0"), "--dt must be a positive", "dt"),
        (_with("--dt", "1"), "reduce --dt", "dt"),  # the integration blows up
        (
            _with("--record-interval", "0"),
            "--record-interval must be a positive",
            "record_interval",
        ),
        # 2 samples: the trace format's refusal, said in the options that make the samples
        (
            _with("--record-interval", "2e-4"),
            "--duration 0.0002 s and --record-interval 0.0002 s",
            "duration",
        ),
        (_with("--sensors", "7"), "--sensors: bead 7 is outside the chain 1..5", "bead:"),
        (_with("--sensors", "0 3"), "--sensors: bead 0 is outside", "bead:"),
        (_with("--sensors", "3 2"), "--sensors: must be strictly increasing", "column"),
        (_with("--sensors", "2 2"), "--sensors: must be strictly increasing", "column"),
        (_with("--sensor-beads", "", "--sensors", "7"), "--sensors: bead 7", "sensor_beads"),
        (_with("--radius", "0"), "--radius must be a positive finite number", "radius"),
        (_with("--eta", "-0.5"), "--eta must be a non-negative", "eta"),
        (_with("--striker-radius", "0"), "--striker-radius must be a positive", "radius"),
        (["theory", "--radius", "-1"], "--radius must be a positive", "radius_a"),
        (["theory", "--force", "0"], "--force must be a positive finite number", "Error"),
        (["theory", "--force", "nan"], "--force must be a positive finite number", "NaN"),
    ],
)
def test_bad_input_exits_2_naming_the_option(arguments, option, library_name, tmp_path,
                                             monkeypatch, capsys):  # fmt: skip
    """Bad input: exit status 2, one line on stderr that names the option as typed (not
    the library's parameter), before any file is written."""
    monkeypatch.chdir(tmp_path)
    assert main([a for a in arguments if a]) == 2
    captured = capsys.readouterr()
    error = captured.err.strip()
    assert error.startswith(f"hertzchain {arguments[0]}: error: ") and "\n" not in error
    assert option in error
    # The library's word is gone once the options are taken out of the message.
    assert library_name not in re.sub(r"(?<![\w-])--?[A-Za-z][\w-]*", "", error)
    assert not captured.out and not (tmp_path / "x.csv").exists()


def test_analyse_names_the_estimator_option_and_the_missing_file(tmp_path, capsys):
    traces = tmp_path / "traces.csv"
    assert main(_with("-o", str(traces))) == 0
    capsys.readouterr()
    assert main(["analyse", str(traces), "--estimator", "fit_all"]) == 2
    assert "unknown --estimator ['fit_all']; choose from" in capsys.readouterr().err
    assert main(["analyse", str(tmp_path / "missing.csv")]) == 2
    assert "missing.csv" in capsys.readouterr().err


def test_option_words_replace_whole_parameter_names_only():
    options = {"dt": "--dt", "v_left": "--speed", "v_right": "--speed", "eta": "--eta"}
    assert in_option_words("eta[contact 3] must be >= 0", options) == "--eta must be >= 0"
    assert in_option_words("v_left or v_right must be > 0", options) == "--speed must be > 0"
    # Not inside a word, a file name or an option already named.
    assert in_option_words("dt.csv: no dt_max; reduce --dt", options) == (
        "dt.csv: no dt_max; reduce --dt"
    )
    assert in_option_words("theta must be finite", options) == "theta must be finite"


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
