"""Figure functions (chain.report.fig*) on small synthetic tables: they return Figures,
draw what the captions say, and save byte-identical PDF/PNG files."""

from __future__ import annotations

import math

import matplotlib as mpl
import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from chain.physics.theory import cos6_pulse
from chain.report.figures import style
from chain.report.figures.fig1_setup import fig1_setup
from chain.report.figures.fig2_experiment_traces import fig2_experiment_traces
from chain.report.figures.fig3_simulation_traces import fig3_simulation_traces
from chain.report.figures.fig4_delay_vs_force import fig4_delay_vs_force
from chain.report.figures.fig5_ssw_vs_force import fig5_ssw_vs_force
from chain.report.figures.fig_parity_ssw_vs_N import fig_parity_ssw_vs_N
from chain.traces import sensor_column, validate_traces

#: Synthetic pulse: duration tau and the arrival times of the incident and crossed
#: pulses at S1 (the crossed pulse arrives DELAY early, the reference on time).
TAU = 80e-6
T_INCIDENT, T_CROSSED, T_REFERENCE_S2 = 400e-6, 800e-6, 810e-6
DT = 2e-6
DURATION = 1.6e-3
FORCES_N = (20.0, 100.0, 300.0, 900.0)


def synthetic_traces(n: int, sensors=(9, 17), source="simulation", model="elastic"):
    """A trace table of one chain: a collision and a reference shot per amplitude."""
    time = np.arange(0.0, DURATION, DT)
    rows = []
    for amplitude, force in enumerate(FORCES_N):
        ssw = 0.05 * force * np.exp(-(((time - T_CROSSED - 1.2 * TAU) / (0.4 * TAU)) ** 2))
        collision = cos6_pulse(time, force, T_INCIDENT, TAU) + cos6_pulse(
            time, 0.95 * force, T_CROSSED, TAU
        )
        shots = {
            ("collision", amplitude): (collision + ssw, collision + ssw),
            ("reference", len(FORCES_N) + amplitude): (
                cos6_pulse(time, force, T_INCIDENT, TAU),
                cos6_pulse(time, 0.96 * force, T_REFERENCE_S2, TAU),
            ),
        }
        for (kind, shot), (s1, s2) in shots.items():
            rows.append(
                pd.DataFrame(
                    {
                        "source": source,
                        "model": model,
                        "N": n,
                        "shot": shot,
                        "kind": kind,
                        "amplitude": amplitude,
                        "v0_left_m_s": 0.3 * (amplitude + 1),
                        "v0_right_m_s": 0.3 * (amplitude + 1) if kind == "collision" else 0.0,
                        "t_s": time,
                        sensor_column(sensors[0]): s1,
                        sensor_column(sensors[1]): s2,
                    }
                )
            )
    return validate_traces(pd.concat(rows, ignore_index=True))


def synthetic_pulses(traces: pd.DataFrame, estimator="fit_full") -> pd.DataFrame:
    rows = []
    for shot, group in traces.groupby("shot"):
        meta = group.iloc[0]
        force = FORCES_N[int(meta["amplitude"])]
        base = {
            "source": meta["source"],
            "model": meta["model"],
            "N": meta["N"],
            "shot": shot,
            "kind": meta["kind"],
            "amplitude": meta["amplitude"],
            "estimator": estimator,
            "tau_s": TAU,
            "ok": True,
            "reason": "",
        }
        if meta["kind"] == "collision":
            for sensor, first, second in (("S1", "LSTW", "RSTW"), ("S2", "RSTW", "LSTW")):
                rows.append(
                    {
                        **base,
                        "sensor": sensor,
                        "role": "incident",
                        "wave": first,
                        "F_m_N": force,
                        "T_s": T_INCIDENT,
                    }
                )
                rows.append(
                    {
                        **base,
                        "sensor": sensor,
                        "role": "crossed",
                        "wave": second,
                        "F_m_N": 0.95 * force,
                        "T_s": T_CROSSED,
                    }
                )
        else:
            rows.append(
                {
                    **base,
                    "sensor": "S1",
                    "role": "reference",
                    "wave": "LSTW",
                    "F_m_N": force,
                    "T_s": T_INCIDENT,
                }
            )
            rows.append(
                {
                    **base,
                    "sensor": "S2",
                    "role": "reference",
                    "wave": "LSTW",
                    "F_m_N": 0.96 * force,
                    "T_s": T_REFERENCE_S2,
                }
            )
    return pd.DataFrame(rows)


def synthetic_ssw(pulses: pd.DataFrame) -> pd.DataFrame:
    crossed = pulses[pulses["role"] == "crossed"]
    table = crossed[["source", "model", "N", "shot", "amplitude", "sensor", "wave"]].copy()
    table["F_m_N"] = crossed["F_m_N"] / 0.95
    table["ssw_N"] = 0.05 * table["F_m_N"]
    table["ssw_time_us"] = (T_CROSSED + 1.2 * TAU) * 1e6
    table["method"] = "residual"
    table["ok"] = True
    return table


def delays_table() -> pd.DataFrame:
    rows = []
    for source, model, c in (
        ("simulation", "elastic", 40.0),
        ("simulation", "viscoelastic", 43.0),
        ("experiment", "rig", 46.0),
    ):
        for n in (25, 26):
            for amplitude, force in enumerate(FORCES_N):
                for wave in ("LSTW", "RSTW"):
                    rows.append(
                        {
                            "source": source,
                            "model": model,
                            "N": n,
                            "shot": amplitude,
                            "amplitude": amplitude,
                            "wave": wave,
                            "estimator": "fit_full",
                            "F_m_N": force * (1.02 if wave == "RSTW" else 1.0),
                            "delay_us": -c * force ** (-1 / 6),
                            "ok": True,
                        }
                    )
    return pd.DataFrame(rows)


def delay_fits_table() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "source": ["simulation", "simulation", "experiment", "simulation", "experiment"],
            "model": ["elastic", "viscoelastic", "rig", "elastic", "rig"],
            "N": ["pooled", "pooled", "pooled", "25", "25"],
            "estimator": "fit_full",
            "C_us_N16": [40.0, 43.0, 46.0, 40.0, 46.1],
            "C_stderr_us_N16": [0.2, 0.2, 0.6, 0.1, 0.8],
            "exponent": -1 / 6,
            "exponent_stderr": 0.003,
            "n_points": 16,
        }
    )


def ssw_tables():
    rows = []
    for source, model in (("simulation", "elastic"), ("experiment", "rig")):
        for n, slope in ((25, 0.02), (26, 0.05)):
            for force in FORCES_N:
                rows.append(
                    {
                        "source": source,
                        "model": model,
                        "N": n,
                        "F_m_N": force,
                        "ssw_N": slope * force,
                        "ssw_err_N": 0.1 * slope * force,
                        "ssw_sys_N": 0.1 * slope * force,
                        "method": "residual",
                        "ok": True,
                        "resolved": n == 26,
                        "upper_limit": False,
                    }
                )
    ssw = pd.DataFrame(rows)
    fits = ssw.groupby(["source", "model", "N"], as_index=False).apply(
        lambda g: pd.Series(
            {
                "slope": (g.ssw_N / g.F_m_N).mean(),
                "slope_stderr": 1e-4,
                "slope_stat": 1e-4,
                "slope_sys": 2e-3,
                "n_points": len(g),
            }
        ),
        include_groups=False,
    )
    fits["method"] = "residual"
    return ssw, fits


@pytest.fixture(scope="module")
def trace_inputs():
    t25 = synthetic_traces(25, (9, 17))
    t26 = synthetic_traces(26, (10, 17))
    pulses = pd.concat([synthetic_pulses(t25), synthetic_pulses(t26)], ignore_index=True)
    return [t25, t26], pulses, synthetic_ssw(pulses)


def line_styles(ax):
    return [(line.get_color(), line.get_linestyle()) for line in ax.get_lines()]


# ---- Fig. 1 --------------------------------------------------------------------------


def test_fig1_draws_one_row_per_chain():
    fig = fig1_setup([{"N": 25, "sensors": [9, 17]}, {"N": 26, "sensors": [10, 17]}])
    assert isinstance(fig, Figure)
    axes = fig.get_axes()
    assert len(axes) == 2
    texts = [t.get_text() for t in axes[1].texts]
    assert "S1 (n = 10)" in texts and "S2 (n = 17)" in texts
    assert "LSTW" in texts and "RSTW" in texts
    assert any("acquisition" in t for t in texts)
    circles = [p for p in axes[0].patches if type(p).__name__ == "Circle"]
    assert len(circles) == 25 + 2  # beads and strikers


def test_fig1_subsamples_many_chains():
    chains = [{"N": n, "sensors": [n // 2 - 3, n + 1 - (n // 2 - 3)]} for n in range(20, 32)]
    fig = fig1_setup(chains, max_rows=4)
    assert len(fig.get_axes()) == 4
    assert "4 of 12 chains" in fig.get_suptitle()


# ---- Fig. 2 / 3 ----------------------------------------------------------------------


def test_fig3_layout_and_styles(trace_inputs):
    traces, pulses, ssw = trace_inputs
    fig = fig3_simulation_traces(traces, pulses, ssw, model="elastic", representative_force_N=280)
    main = [ax for ax in fig.get_axes() if ax.get_title(loc="left")]
    titles = sorted(ax.get_title(loc="left") for ax in main)
    assert [t.split(")")[0] for t in titles] == ["(A", "(B", "(C", "(D"]
    assert "N = 25, S1 at n = 9" in titles[0] and "F$_m$ = 300 N" in titles[0]
    assert "N = 26, S2 at n = 17" in titles[3]
    by_title = {ax.get_title(loc="left")[:3]: ax for ax in main}
    s1_styles = line_styles(by_title["(A)"])
    # reference dotted, then LSTW solid (incident) and RSTW dashed (crossed) at S1.
    assert s1_styles == [
        (style.REFERENCE_COLOR, ":"),
        (style.LSTW_COLOR, "-"),
        (style.RSTW_COLOR, "--"),
    ]
    s2_styles = line_styles(by_title["(B)"])
    assert s2_styles[1:] == [(style.RSTW_COLOR, "--"), (style.LSTW_COLOR, "-")]
    insets = [inset for ax in main for inset in ax.child_axes]
    assert len(insets) == 4
    assert all(any("SSW 15 N" in t.get_text() for t in inset.texts) for inset in insets)


def test_fig3_split_is_at_the_minimum_between_pulses(trace_inputs):
    traces, pulses, _ = trace_inputs
    fig = fig3_simulation_traces(
        traces[:1], pulses, None, model="elastic", representative_index=1, inset=False
    )
    ax = fig.get_axes()[0]
    lstw = ax.get_lines()[1].get_xdata()
    split_us = lstw[-1]
    assert T_INCIDENT * 1e6 + TAU * 1e6 < split_us < T_CROSSED * 1e6 - TAU * 1e6
    assert len(fig.get_axes()) == 2
    assert not fig.get_axes()[0].child_axes


def test_fig3_without_pulse_table_picks_by_peak(trace_inputs):
    traces, _, _ = trace_inputs
    fig = fig3_simulation_traces(traces, model="elastic", representative_force_N=900)
    ax = next(a for a in fig.get_axes() if a.get_title(loc="left"))
    peak = max(np.max(line.get_ydata()) for line in ax.get_lines())
    assert peak == pytest.approx(900.0, rel=0.01)


def test_fig2_takes_experiment_traces(trace_inputs):
    _, _, _ = trace_inputs
    traces = synthetic_traces(25, (9, 17), source="experiment", model="rig")
    pulses = synthetic_pulses(traces)
    fig = fig2_experiment_traces([traces], pulses, label="virtual experiment (model)")
    assert fig.get_suptitle().startswith("virtual experiment (model)")
    with pytest.raises(ValueError, match="no experiment traces"):
        fig2_experiment_traces([synthetic_traces(25)])


def test_fig2_draws_a_shot_the_protocol_kept(trace_inputs):
    traces = synthetic_traces(25, (9, 17), source="experiment", model="rig")
    pulses = synthetic_pulses(traces)
    # The collision nearest 300 N (amplitude 2, shot 2) was rejected: the nearest
    # amplitude with a kept collision is drawn instead.
    selection = pd.DataFrame(
        {
            "source": "experiment",
            "model": "rig",
            "N": 25,
            "shot": sorted(traces["shot"].unique()),
        }
    )
    selection["kept"] = selection["shot"] != 2
    fig = fig2_experiment_traces(
        [traces], pulses, representative_force_N=300.0, selection=selection, label="lab"
    )
    title = next(ax.get_title(loc="left") for ax in fig.get_axes() if ax.get_title(loc="left"))
    assert "F$_m$ = 100 N" in title or "F$_m$ = 900 N" in title
    everything = fig2_experiment_traces([traces], pulses, representative_force_N=300.0)
    title = next(
        ax.get_title(loc="left") for ax in everything.get_axes() if ax.get_title(loc="left")
    )
    assert "F$_m$ = 300 N" in title
    assert everything.get_suptitle() == "experiment: forces at the sensor beads (series rig)"


def test_trace_inset_stays_clear_of_the_traces(trace_inputs):
    """A short record fills the width with the two pulses: the y axis makes room."""
    traces = synthetic_traces(25, (9, 17), source="experiment", model="rig")
    short = traces[traces["t_s"] < 1.0e-3]
    pulses = synthetic_pulses(short)
    fig = fig2_experiment_traces([short], pulses, ssw=synthetic_ssw(pulses))
    fig.draw_without_rendering()  # final positions (constrained layout)
    for ax in (a for a in fig.get_axes() if a.get_title(loc="left")):
        (inset,) = ax.child_axes
        box = inset.get_window_extent()
        for line in ax.get_lines():
            points = ax.transData.transform(np.column_stack(line.get_data()))
            under = (points[:, 0] >= box.x0) & (points[:, 0] <= box.x1)
            assert np.all(points[under, 1] < box.y0), ax.get_title(loc="left")


# ---- Fig. 4 / 5 / parity -------------------------------------------------------------


def test_fig4_lines_fits_and_references():
    constants = {"C_bal_paper_us_N16": 49.75, "C_bal_exact_us_N16": 37.74}
    fig = fig4_delay_vs_force(
        delays_table(),
        delay_fits_table(),
        constants=constants,
        experiment_label="virtual experiment (model)",
    )
    ax = fig.get_axes()[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert "(N)" in ax.get_xlabel() and "(µs)" in ax.get_ylabel()
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    # One name per series everywhere (chain.report.naming): the label names the virtual
    # series, so another series of its rows ("rig") is named after it.
    assert sum(label.startswith("simulation, ") for label in labels) == 4
    # Experiment markers carry their chain's own fit; the dashed line is the pooled fit.
    assert "virtual experiment (model), rig, N = 25 (own fit C = 46.1 ± 0.8)" in labels
    assert "virtual experiment (model), rig, N = 26" in labels
    assert any(
        label.startswith("fit to virtual experiment (model), rig, N pooled: C = 46.0 ± 0.6")
        for label in labels
    )
    # An error of 0.2 keeps two figures (leading digits 10-35, chain.report.printed).
    assert any("fit to simulation, elastic: C = 40.00 ± 0.20" in label for label in labels)
    assert any("Eq. 6 as printed" in label and "49.75" in label for label in labels)
    assert any("exact Hertz" in label and "37.74" in label for label in labels)
    assert any("paper's experimental fit" in label and "45.9 ± 0.5" in label for label in labels)
    markers = {line.get_label(): line for line in ax.get_lines()}
    n25 = markers["virtual experiment (model), rig, N = 25 (own fit C = 46.1 ± 0.8)"]
    assert n25.get_marker() == "o" and n25.get_markerfacecolor() == "none"
    assert markers["virtual experiment (model), rig, N = 26"].get_marker() == "x"
    fits = [
        line for line in ax.get_lines() if " fit" in line.get_label() or "fit " in line.get_label()
    ]
    fits = [line for line in fits if line.get_linestyle() != "None"]
    assert len(fits) == 4  # one per simulated model, the experiment's, the paper's C_exp
    assert all(line.get_linestyle() == "--" for line in fits[:3])


def test_fig4_and_fig5_leave_out_flagged_and_nan_rows_with_a_logged_count(caplog):
    delays = delays_table()
    experiment = delays.index[delays["source"] == "experiment"]
    delays.loc[experiment[:3], "ok"] = False  # flagged
    delays.loc[experiment[3], "delay_us"] = math.nan  # ok but NaN: a bug upstream
    with caplog.at_level("INFO", logger="chain.analysis.rows"):
        fig = fig4_delay_vs_force(delays, experiment_label="x")
    drawn = sum(
        len(line.get_xdata())
        for line in fig.get_axes()[0].get_lines()
        if line.get_label().startswith("x, rig, N = ")
    )
    assert drawn == len(experiment) - 4
    assert "Fig. 4 (fit_full): 4 of 48 left out (3 flagged ok = False, 1 ok but NaN" in caplog.text

    ssw, fits = ssw_tables()
    ssw.loc[0, "ok"] = False
    ssw.loc[1, "ssw_N"] = math.nan
    ssw.loc[2, ["ssw_N", "upper_limit"]] = (-0.1, True)  # an upper limit: drawn at value + error
    caplog.clear()
    with caplog.at_level("INFO", logger="chain.analysis.rows"):
        fig = fig5_ssw_vs_force(ssw, fits)
    points = [container.lines[0] for container in fig.get_axes()[0].containers]
    assert sum(len(line.get_xdata()) for line in points) == len(ssw) - 2
    assert "Fig. 5 SSW rows: 2 of 16 left out (1 flagged ok = False, 1 ok but NaN" in caplog.text


def test_fig4_on_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    assert fig4_delay_vs_force(delays_table(), ax=ax) is fig
    assert ax.get_legend() is not None and not fig.legends


def test_fig5_resolved_filled_measured_open_upper_limits_arrowed():
    ssw, fits = ssw_tables()
    limits = (ssw["N"] == 25) & (ssw["source"] == "experiment")
    ssw.loc[limits, "upper_limit"] = True
    fig = fig5_ssw_vs_force(ssw, fits, experiment_label="virtual experiment (model)")
    ax = fig.get_axes()[0]
    drawn = [container.lines[0] for container in ax.containers]
    filled = [line for line in drawn if line.get_markerfacecolor() not in ("white", "none")]
    # Resolved (N = 26, both series) filled; the rest open.
    assert sum(len(line.get_xdata()) for line in filled) == int(ssw["resolved"].sum())
    # Upper limits are drawn at value + error, with arrows (caps of the error bars).
    level = (ssw.loc[limits, "ssw_N"] + ssw.loc[limits, "ssw_err_N"]).to_numpy()
    assert any(
        len(line.get_ydata()) == len(level)
        and np.allclose(np.sort(line.get_ydata()), np.sort(level))
        for line in drawn
    )
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    label = next(t for t in labels if t.startswith("virtual experiment (model), rig, N = 26"))
    assert (
        "5.00 ± 0.01 (stat) ± 0.20 (sys)" in label
        and f"{len(FORCES_N)} of {len(FORCES_N)} resolved" in label
    )
    assert ax.get_ylabel() == "SSW amplitude (N)"


def test_fig5_panel_b_from_the_track():
    ssw, fits = ssw_tables()
    track = pd.DataFrame(
        {
            "model": "elastic",
            "N": 26,
            "wave": "LSTW",
            "distance_beads": [3.0, 4.0, 5.0],
            "force_N": [np.nan, 2.0, 1.8],
            "F_m_N": 100.0,
            "separated": [False, True, True],
        }
    )
    speed = pd.DataFrame({"model": ["elastic"], "wave": ["LSTW"], "distance_beads": [4.0]})
    fig = fig5_ssw_vs_force(ssw, fits, track, speed, sensor_distances={26: 3.5})
    ax = fig.get_axes()[1]
    points = [line for line in ax.get_lines() if line.get_label() == "elastic, N = 26"]
    np.testing.assert_allclose(points[0].get_ydata(), [0.02, 0.018])
    dotted = [
        line for line in ax.get_lines() if line.get_linestyle() == ":" and len(line.get_xdata())
    ]
    assert [line.get_xdata()[0] for line in dotted] == [4.0]


def test_fig5_panel_b_says_so_when_no_chain_separates_an_ssw(tmp_path):
    """Chains too short for the SSW to separate (none separated): panel (b) is drawn,
    saying so, instead of failing on an empty log axis."""
    ssw, fits = ssw_tables()
    track = pd.DataFrame(
        {"model": "elastic", "N": 16, "wave": "LSTW", "distance_beads": [3.0, 4.0],
         "force_N": np.nan, "F_m_N": 100.0, "separated": False}
    )  # fmt: skip
    fig = fig5_ssw_vs_force(ssw, fits, track, None, sensor_distances={16: 3.5})
    fig.savefig(tmp_path / "fig5.png")
    texts = [t.get_text() for t in fig.get_axes()[1].texts]
    assert texts == ["no separated SSW on any chain of this run"]


def test_parity_figure():
    rows = [
        {
            "source": "simulation",
            "model": "elastic",
            "N": n,
            "slope": 0.05 if n % 2 == 0 else 0.02,
            "slope_stderr": 1e-3,
            "n_points": 8,
            "method": "residual",
        }
        for n in range(20, 32)
    ]
    fig = fig_parity_ssw_vs_N(pd.DataFrame(rows))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["simulation, elastic, even N", "simulation, elastic, odd N"]


# ---- saving --------------------------------------------------------------------------


def test_save_figure_is_byte_reproducible(tmp_path, trace_inputs):
    traces, pulses, ssw = trace_inputs
    paths = []
    for name in ("a", "b"):
        fig = fig3_simulation_traces(traces, pulses, ssw, model="elastic")
        paths.append(style.save_figure(fig, tmp_path / name / "fig3_simulation_traces"))
    for first, second in zip(*paths):
        assert first.read_bytes() == second.read_bytes(), first.name
    pdf, png = paths[0]
    assert pdf.name == "fig3_simulation_traces.pdf" and pdf.read_bytes().startswith(b"%PDF")
    assert png.read_bytes().startswith(b"\x89PNG")
    assert b"CreationDate" not in pdf.read_bytes()
    assert b"Software" not in png.read_bytes() and b"matplotlib" not in png.read_bytes().lower()
    assert sorted(p.name for p in pdf.parent.iterdir()) == [pdf.name, png.name]
    mode = pdf.stat().st_mode & 0o777
    assert mode & 0o044, "figures must be readable by others (not left at mkstemp's 0600)"


@pytest.mark.parametrize("figure", ["fig3", "fig4", "fig5", "parity"])
def test_pdf_and_png_drawn_at_once_have_the_bytes_of_one_after_the_other(
    tmp_path, trace_inputs, figure
):
    """save_figure(processes=2) draws the PNG in a forked process: the same bytes."""
    traces, pulses, ssw = trace_inputs
    builders = {
        "fig3": lambda: fig3_simulation_traces(traces, pulses, ssw, model="elastic"),
        "fig4": lambda: fig4_delay_vs_force(
            delays_table(),
            delay_fits_table(),
            constants={"C_bal_paper_us_N16": 49.75, "C_bal_exact_us_N16": 37.74},
        ),
        "fig5": lambda: fig5_ssw_vs_force(*ssw_tables()),
        "parity": lambda: fig_parity_ssw_vs_N(ssw_tables()[1]),
    }
    one, two = (
        style.save_figure(builders[figure](), tmp_path / str(n) / figure, processes=n)
        for n in (1, 2)
    )
    for sequential, side_by_side in zip(one, two, strict=True):
        assert sequential.read_bytes() == side_by_side.read_bytes(), sequential.name
    assert sorted(p.name for p in two[0].parent.iterdir()) == [f"{figure}.pdf", f"{figure}.png"]


def test_a_png_that_fails_in_its_process_fails_the_save_and_leaves_no_file(tmp_path, monkeypatch):
    def broken(fig, target):
        raise OSError("disk full")

    monkeypatch.setattr(style, "_save_png", broken)  # in the forked child too
    fig = style.new_figure(2.0, 2.0)
    fig.add_subplot().plot([0, 1], [1, 0])
    with pytest.raises(RuntimeError, match=r"fails\.png failed in its process"):
        style.save_figure(fig, tmp_path / "fails", processes=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fails.pdf"]


def test_pdf_layout_pass_rasterizes_nothing_and_changes_no_byte(tmp_path, monkeypatch):
    """save_figure rasterizes a rasterized artist once for the PDF (its layout pass,
    which draws nothing, skips it) and writes the bytes matplotlib's own savefig does."""
    from matplotlib.backends.backend_mixed import MixedModeRenderer

    def mesh_figure() -> Figure:
        fig = style.new_figure(3.0, 2.0)
        ax = fig.add_subplot()
        values = np.outer(np.arange(1.0, 31.0), np.arange(1.0, 41.0))
        ax.pcolormesh(np.arange(40.0), np.arange(30.0), values, rasterized=True)
        ax.set_title("mesh")
        return fig

    rasterized = []
    start = MixedModeRenderer.start_rasterizing
    monkeypatch.setattr(
        MixedModeRenderer, "start_rasterizing", lambda r: rasterized.append(1) or start(r)
    )
    ours = style.save_figure(mesh_figure(), tmp_path / "ours" / "mesh")
    assert len(rasterized) == 1, "the PDF rasterizes once (the PNG is all pixels)"
    plain = tmp_path / "plain"
    plain.mkdir()
    fig = mesh_figure()
    with mpl.rc_context(style.STYLE):
        fig.savefig(plain / "mesh.pdf", metadata=style.PDF_METADATA)
        fig.savefig(plain / "mesh.png", metadata=style.PNG_METADATA, dpi=style.PNG_DPI)
    for path in ours:
        assert path.read_bytes() == (plain / path.name).read_bytes(), path.name


def test_model_colors_and_markers():
    colors = style.model_colors(["elastic", "viscoelastic", "custom"])
    assert colors["elastic"] != colors["viscoelastic"] != colors["custom"]
    assert style.chain_marker(25) == "o" and style.chain_marker(26) == "x"
    assert style.chain_marker(20, [20, 21]) != style.chain_marker(21, [20, 21])
    assert math.isfinite(style.PNG_DPI)


# ---- SSW markers: on the SSW's maximum, or "not resolved" ----------------------------


def test_fig3_ssw_marker_points_at_the_ssw_maximum(trace_inputs):
    traces, pulses, ssw = trace_inputs
    fig = fig3_simulation_traces(traces, pulses, ssw, model="elastic", representative_force_N=280)
    t_ssw = (T_CROSSED + 1.2 * TAU) * 1e6
    for ax in (a for a in fig.get_axes() if a.get_title(loc="left")):
        inset = ax.child_axes[0]
        signal, marker = inset.get_lines()[-2], inset.get_lines()[-1]
        assert marker.get_marker() == "v"
        assert marker.get_xdata()[0] == pytest.approx(t_ssw)
        # Just above the signal at that time (the bump), not at the top of the inset.
        level = np.interp(t_ssw, signal.get_xdata(), signal.get_ydata())
        assert level < marker.get_ydata()[0] < level + 0.1 * inset.get_ylim()[1]


def test_fig3_says_when_the_ssw_is_not_resolved(trace_inputs):
    traces, pulses, ssw = trace_inputs
    unresolved = ssw.assign(ok=False, ssw_N=math.nan, ssw_time_us=math.nan)
    fig = fig3_simulation_traces(traces, pulses, unresolved, model="elastic")
    insets = [inset for ax in fig.get_axes() for inset in ax.child_axes]
    assert len(insets) == 4
    for inset in insets:
        assert any("SSW not resolved" in t.get_text() for t in inset.texts)
        assert not any(line.get_marker() == "v" for line in inset.get_lines())
    # No SSW marker drawn: none in the legend either.
    assert not any("SSW" in t.get_text() for t in fig.legends[0].get_texts())


def test_fig5_series_without_measurable_points_says_so_in_the_legend():
    ssw, fits = ssw_tables()
    gone = (ssw["source"] == "simulation") & (ssw["N"] == 26)
    ssw.loc[gone, "ok"] = False
    fig = fig5_ssw_vs_force(ssw, fits)
    ax = fig.get_axes()[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    empty = [label for label in labels if "no measurable SSW" in label]
    assert empty and all("N = 26" in label and "(0 of" in label for label in empty)
    drawn = sum(len(container.lines[0].get_xdata()) for container in ax.containers)
    assert drawn == int((~gone).sum())
    # Nothing measurable anywhere: axes that say so.
    ssw["ok"] = False
    fig = fig5_ssw_vs_force(ssw, fits)
    assert any("no measurable SSW" in t.get_text() for t in fig.get_axes()[0].texts)


def test_parity_figure_without_any_resolved_ssw_says_so():
    fits = pd.DataFrame(
        {"source": "simulation", "model": "elastic", "N": [25, 26], "slope": math.nan,
         "slope_stderr": math.nan, "n_points": 0, "method": "residual"}
    )  # fmt: skip
    fig = fig_parity_ssw_vs_N(fits)
    assert any("not resolved" in t.get_text() for t in fig.get_axes()[0].texts)
