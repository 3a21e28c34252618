"""The space-time figure on real tracks of the paper's two chains: one field panel per
chain with the waves drawn over it, and the SSW amplitude panel saying which series
never separate; the field pooled to the figure's time bins keeps every peak."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from chain.analysis.ssw_track import Field, pooled_field, ssw_track_table
from chain.physics.builders import uniform_chain
from chain.physics.simulation import simulate
from chain.report.figures.fig_ssw_spacetime import fig_ssw_spacetime
from chain.report.figures.style import save_figure


@pytest.fixture(scope="module")
def tracked():
    fields, tracks = {}, []
    for n in (25, 26):
        result = simulate(uniform_chain(n), [0.3], [0.3], duration=2.0e-3, record_interval=2e-6)
        tracks.append(
            ssw_track_table(result.time, result.contact_force, source="simulation", model="elastic")
        )
        fields[n] = (pooled_field(result.time, result.contact_force, bins=300), 0)
    return fields, pd.concat(tracks, ignore_index=True)


def test_a_pooled_field_keeps_each_bins_largest_force_and_saves_whole(tmp_path):
    """Each bin holds the largest force of its samples (a 1 % SSW peak stays), its time
    is the bins' centre; written and read back without a pickle, the same arrays."""
    time = np.arange(10) * 1e-6
    force = np.zeros((1, 10, 2))
    force[0, 3, 0], force[0, 8, 1] = 5.0, 0.25  # exact in float32, as the field is kept
    field = pooled_field(time, force, bins=5)
    np.testing.assert_array_equal(field.force_N[0], [[0, 5, 0, 0, 0], [0, 0, 0, 0, 0.25]])
    np.testing.assert_allclose(field.time_us, [0.5, 2.5, 4.5, 6.5, 8.5])
    field.save(tmp_path / "field.npz")
    read = Field.load(tmp_path / "field.npz")
    np.testing.assert_array_equal(read.force_N, field.force_N)
    np.testing.assert_array_equal(read.time_us, field.time_us)


def test_spacetime_panels_and_legend(tracked):
    fields, track = tracked
    fig = fig_ssw_spacetime(fields, track, "elastic")
    assert isinstance(fig, Figure)
    field_axes = [ax for ax in fig.axes if ax.get_ylabel().startswith("contact k")]
    assert len(field_axes) == 2
    # Two main waves (dashed incident, solid crossed) per wave, and the SSW markers.
    for ax, n in zip(field_axes, (25, 26)):
        assert f"N = {n}" in ax.get_title(loc="left")
        assert len(ax.lines) == 6
    ssw_axis = fig.axes[2]
    labels = [text.get_text() for text in ssw_axis.get_legend().get_texts()]
    assert labels == ["elastic, N = 25: never separated", "elastic, N = 26"]
    # The 26-bead SSW is drawn where it is separated, at 4 beads and beyond.
    distances = ssw_axis.lines[1].get_xdata()
    assert len(distances) > 0 and min(distances) >= 4.0


def test_spacetime_figure_is_byte_reproducible(tracked, tmp_path):
    fields, track = tracked
    paths = [
        save_figure(fig_ssw_spacetime(fields, track, "elastic"), tmp_path / name / "ssw_spacetime")
        for name in ("a", "b")
    ]
    for first, second in zip(*paths):
        assert first.read_bytes() == second.read_bytes(), first.name


def test_spacetime_figure_drawn_in_two_processes_has_the_bytes_of_one(tracked, tmp_path):
    """The rule gives this figure two cores: PNG and PDF drawn at once, same bytes."""
    fields, track = tracked
    one, two = (
        save_figure(
            fig_ssw_spacetime(fields, track, "elastic"),
            tmp_path / str(processes) / "ssw_spacetime",
            processes=processes,
        )
        for processes in (1, 2)
    )
    for sequential, side_by_side in zip(one, two, strict=True):
        assert sequential.read_bytes() == side_by_side.read_bytes(), sequential.name
