"""The measured-trace format: loading, conversion, and one message per kind of bad input."""

import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from chain.apparatus.measured import (
    METADATA_FILE,
    STANDARD_GRAVITY,
    MeasuredDataError,
    load_dataset,
    read_metadata,
    write_metadata,
    write_shot_csv,
)
from chain.traces import META_COLUMNS, validate_traces

EXAMPLE = Path(__file__).parent / "data" / "virtual_small"


# ----------------------------------------------------------------------------- example


def test_example_dataset_loads_as_a_trace_table():
    table = load_dataset(EXAMPLE)
    validate_traces(table)
    assert list(table.columns) == [*META_COLUMNS, "force_bead9_N", "force_bead17_N"]
    assert set(table["source"]) == {"experiment"}
    assert set(table["model"]) == {"virtual_small"}  # the metadata name
    assert set(table["N"]) == {25}
    shots = table.groupby("shot").first()
    assert list(shots["kind"]) == ["collision", "collision", "reference"] * 2
    assert list(shots["amplitude"]) == [0, 0, 0, 1, 1, 1]
    # v0 = sqrt(2 g h) from the drop heights 5 cm and 20 cm; 0 on the right for references
    speeds = np.sqrt(2 * STANDARD_GRAVITY * np.array([0.05, 0.2]))
    assert shots["v0_left_m_s"].to_numpy() == pytest.approx(np.repeat(speeds, 3))
    assert shots["v0_right_m_s"].to_numpy() == pytest.approx(
        [speeds[0]] * 2 + [0] + [speeds[1]] * 2 + [0]
    )
    # newtons: the incident waves of a 5 cm drop are ~25 N at S1 (the truth file's speeds)
    peak = table.groupby("shot")["force_bead9_N"].max()
    assert 15 < peak[0] < 40 and peak[3] > 1.8 * peak[0]
    assert load_dataset(EXAMPLE, name="lab").loc[0, "model"] == "lab"


def test_volts_are_divided_by_the_sensitivity_of_each_sensor(tmp_path):
    time = np.arange(5) * 1e-6
    volts = np.array([[0.0, 0.1124, 0.2248, 0.1124, 0.0], [0.0, 0.0, 0.05, 0.1, 0.0]])
    write_shot_csv(tmp_path / "a.csv", time, volts, (2, 5))
    write_metadata(
        tmp_path,
        {
            "N": 6,
            "sensor_beads": [2, 5],
            "sensitivity_mV_per_N": [11.24, 5.0],
            "sampling_interval_s": 1e-6,
            "shots": [{"file": "a.csv", "kind": "collision", "amplitude": "high"}],
        },
    )
    table = load_dataset(tmp_path)
    assert table["force_bead2_N"].to_numpy() == pytest.approx([0, 10, 20, 10, 0])
    assert table["force_bead5_N"].to_numpy() == pytest.approx([0, 0, 10, 20, 0])
    assert table["model"].iloc[0] == tmp_path.name  # no name: the folder's
    assert np.isnan(table["v0_left_m_s"]).all()  # no drop height: unknown


# ----------------------------------------------------------------------------- bad input

GOOD_METADATA = """\
N: 12
sensor_beads: [4, 9]
sensitivity_mV_per_N: 11.24
sampling_interval_s: 1.0e-6
shots:
  - {file: s0.csv, kind: collision, drop_height_m: 0.05}
  - {file: s1.csv, kind: collision, drop_height_m: 0.10}
  - {file: s2.csv, kind: reference, drop_height_m: 0.05}
"""


def _good_csv() -> list[str]:
    lines = ["t_s,bead4_V,bead9_V"]
    for k in range(8):
        lines.append(f"{k * 1e-6:.10g},{0.01 * k:.6g},{0.02 * k:.6g}")
    return lines


@pytest.fixture
def dataset(tmp_path):
    folder = tmp_path / "lab"
    folder.mkdir()
    (folder / METADATA_FILE).write_text(GOOD_METADATA)
    for name in ("s0.csv", "s1.csv", "s2.csv"):
        (folder / name).write_text("\n".join(_good_csv()) + "\n")
    return folder


def test_good_dataset_loads_and_groups_by_drop_height(dataset):
    table = load_dataset(dataset)
    shots = table.groupby("shot").first()
    assert list(shots["amplitude"]) == [0, 1, 0]
    assert shots.loc[1, "v0_left_m_s"] == pytest.approx(math.sqrt(2 * STANDARD_GRAVITY * 0.1))
    assert table.loc[1, "force_bead9_N"] == pytest.approx(0.02 / 11.24e-3)


def _csv(edit):
    """A case that edits the lines of s1.csv (line n of the file is lines[n - 1])."""

    def apply(folder):
        lines = _good_csv()
        edit(lines)
        (folder / "s1.csv").write_text("\n".join(lines) + "\n")

    return apply


def _raw_csv(text):
    def apply(folder):
        (folder / "s1.csv").write_text(text)

    return apply


def _meta(edit):
    """A case that edits the parsed metadata mapping."""

    def apply(folder):
        mapping = yaml.safe_load(GOOD_METADATA)
        edit(mapping)
        (folder / METADATA_FILE).write_text(yaml.safe_dump(mapping, sort_keys=False))

    return apply


def _meta_text(old, new):
    def apply(folder):
        (folder / METADATA_FILE).write_text(GOOD_METADATA.replace(old, new))

    return apply


def _set(lines, number, text):
    lines[number - 1] = text


def _drop_last_column(folder):
    lines = [line.rsplit(",", 1)[0] for line in _good_csv()]
    (folder / "s1.csv").write_text("\n".join(lines) + "\n")


def _add_column(folder):
    lines = [line + ",0" for line in _good_csv()]
    lines[0] = "t_s,bead4_V,bead9_V,bead5_V"
    (folder / "s1.csv").write_text("\n".join(lines) + "\n")


def _truncate(folder):
    text = "\n".join(_good_csv())
    (folder / "s1.csv").write_text(text[: text.rindex(",")])  # cut inside the last line


# (case id, mutation, file named in the message, expected fragment)
BAD_INPUT = [
    (
        "missing column",
        _drop_last_column,
        "s1.csv",
        "line 1: missing columns ['bead9_V']",
    ),
    (
        "extra column",
        _add_column,
        "s1.csv",
        "line 1: unexpected columns ['bead5_V']",
    ),
    (
        "columns out of order",
        _csv(lambda ls: _set(ls, 1, "t_s,bead9_V,bead4_V")),
        "s1.csv",
        "line 1: columns must be in the order t_s,bead4_V,bead9_V",
    ),
    (
        "time goes back",
        _csv(lambda ls: _set(ls, 6, "2.5e-06,0.04,0.08")),
        "s1.csv",
        "line 6: column t_s: time 2.5e-06 s does not increase",
    ),
    (
        "repeated time",
        _csv(lambda ls: _set(ls, 4, "1e-06,0.02,0.04")),
        "s1.csv",
        "line 4: column t_s: time 1e-06 s does not increase",
    ),
    (
        "uneven time",
        _csv(lambda ls: _set(ls, 5, "3.5e-06,0.03,0.06")),
        "s1.csv",
        "line 5: column t_s: time step 1.5e-06 s differs from sampling_interval_s 1e-06 s",
    ),
    (
        "time in microseconds",
        _csv(
            lambda ls: [
                _set(ls, i + 1, f"{i - 1},{ls[i].split(',', 1)[1]}") for i in range(1, len(ls))
            ]
        ),
        "s1.csv",
        "line 3: column t_s: 7 of 7 time steps (1 s typically) differ from sampling_interval_s",
    ),
    (
        "NaN value",
        _csv(lambda ls: _set(ls, 4, "2e-06,nan,0.04")),
        "s1.csv",
        "line 4: column bead4_V: missing or non-finite value 'nan'",
    ),
    (
        "empty field",
        _csv(lambda ls: _set(ls, 7, "5e-06,0.05,")),
        "s1.csv",
        "line 7: column bead9_V: missing value (empty field)",
    ),
    (
        "not a number",
        _csv(lambda ls: _set(ls, 3, "1e-06,0.01,abc")),
        "s1.csv",
        "line 3: column bead9_V: 'abc' is not a number",
    ),
    (
        "blank line inside",
        _csv(lambda ls: _set(ls, 5, "")),
        "s1.csv",
        "line 5: 1 fields, expected 3",
    ),
    ("empty file", _raw_csv(""), "s1.csv", "empty file"),
    ("header only", _raw_csv("t_s,bead4_V,bead9_V\n"), "s1.csv", "0 data rows, need at least 3"),
    ("truncated file", _truncate, "s1.csv", "line 9: 2 fields, expected 3 (truncated file?)"),
    (
        "semicolon export",
        _csv(lambda ls: [_set(ls, i + 1, ls[i].replace(",", ";")) for i in range(len(ls))]),
        "s1.csv",
        "line 1: missing columns",
    ),
    (
        "metadata names a missing file",
        _meta_text("s1.csv", "s7.csv"),
        "metadata.yaml",
        "line 7: shots[1].file names a missing file 's7.csv'",
    ),
    ("no metadata", lambda f: (f / METADATA_FILE).unlink(), "metadata.yaml", "no such file"),
    ("empty metadata", _meta_text(GOOD_METADATA, ""), "metadata.yaml", "empty file"),
    ("invalid YAML", _meta_text("[4, 9]", "[4, 9"), "metadata.yaml", "not valid YAML"),
    (
        "missing key",
        _meta(lambda m: m.pop("sampling_interval_s")),
        "metadata.yaml",
        "missing keys ['sampling_interval_s']",
    ),
    (
        "unknown key",
        _meta_text("N: 12", "N: 12\nsensitvity_mV_per_N: 11.2"),
        "metadata.yaml",
        "line 2: sensitvity_mV_per_N: unknown key",
    ),
    (
        "N not an integer",
        _meta_text("N: 12", "N: twelve"),
        "metadata.yaml",
        "line 1: N: must be an integer, got 'twelve'",
    ),
    ("N a float", _meta_text("N: 12", "N: 12.5"), "metadata.yaml", "N: must be an integer"),
    (
        "sensor outside the chain",
        _meta_text("[4, 9]", "[4, 30]"),
        "metadata.yaml",
        "line 2: sensor_beads[1]: bead 30 is outside the chain 1..12",
    ),
    (
        "sensor bead zero",
        _meta_text("[4, 9]", "[0, 9]"),
        "metadata.yaml",
        "sensor_beads[0]: must be >= 1, got 0",
    ),
    (
        "sensors not increasing",
        _meta_text("[4, 9]", "[9, 4]"),
        "metadata.yaml",
        "sensor_beads: must be strictly increasing (S1 first)",
    ),
    (
        "sensor_beads not a list",
        _meta_text("[4, 9]", "'4, 9'"),
        "metadata.yaml",
        "sensor_beads: must be a list of bead numbers",
    ),
    (
        "sensitivity text",
        _meta_text("11.24", "eleven"),
        "metadata.yaml",
        "line 3: sensitivity_mV_per_N: must be a number, got 'eleven'",
    ),
    (
        "sensitivity negative",
        _meta_text("11.24", "-11.24"),
        "metadata.yaml",
        "sensitivity_mV_per_N: must be a positive finite number",
    ),
    (
        "one sensitivity for two sensors",
        _meta_text("11.24", "[11.24]"),
        "metadata.yaml",
        "sensitivity_mV_per_N: needs one value per sensor (2), got 1",
    ),
    (
        "interval zero",
        _meta_text("1.0e-6", "0"),
        "metadata.yaml",
        "sampling_interval_s: must be a positive finite number",
    ),
    (
        "shots empty",
        _meta(lambda m: m.update(shots=[])),
        "metadata.yaml",
        "shots: must be a non-empty list",
    ),
    (
        "shot without kind",
        _meta(lambda m: m["shots"][2].pop("kind")),
        "metadata.yaml",
        "shots[2]: missing keys ['kind']",
    ),
    (
        "bad kind",
        _meta_text("kind: reference", "kind: single"),
        "metadata.yaml",
        "line 8: shots[2].kind: must be one of ['collision', 'reference'], got 'single'",
    ),
    (
        "unknown shot key",
        _meta_text("drop_height_m: 0.10", "drop_hieght_m: 0.10"),
        "metadata.yaml",
        "shots[1].drop_hieght_m: unknown key",
    ),
    (
        "drop height text",
        _meta_text("drop_height_m: 0.10", "drop_height_m: ten cm"),
        "metadata.yaml",
        "shots[1].drop_height_m: must be a number, got 'ten cm'",
    ),
    (
        "no amplitude information",
        _meta_text(", drop_height_m: 0.10", ""),
        "metadata.yaml",
        "shots[1]: needs amplitude, drop_height_m or impact_speed_m_s",
    ),
    (
        "amplitude for some shots only",
        _meta_text("drop_height_m: 0.10", "amplitude: 1"),
        "metadata.yaml",
        "shots[0]: amplitude is given for some shots but not this one",
    ),
    (
        "height and speed",
        _meta_text("drop_height_m: 0.10", "drop_height_m: 0.1, impact_speed_m_s: 1.4"),
        "metadata.yaml",
        "shots[1]: give drop_height_m or impact_speed_m_s, not both",
    ),
    (
        "file listed twice",
        _meta_text("s2.csv", "s0.csv"),
        "metadata.yaml",
        "shots[2].file: 's0.csv' is already listed as shots[0]",
    ),
    (
        "absolute file",
        _meta_text("s2.csv", "/etc/passwd"),
        "metadata.yaml",
        "shots[2].file: must be relative to the dataset",
    ),
    (
        "wrong format tag",
        _meta_text("N: 12", "format: other/2\nN: 12"),
        "metadata.yaml",
        "format: must be 'hertzchain-measured-traces/1'",
    ),
]


@pytest.mark.parametrize(
    ("mutate", "file", "fragment"),
    [case[1:] for case in BAD_INPUT],
    ids=[case[0] for case in BAD_INPUT],
)
def test_bad_input_names_file_and_line(dataset, mutate, file, fragment):
    mutate(dataset)
    with pytest.raises(MeasuredDataError) as caught:
        load_dataset(dataset)
    message = str(caught.value)
    assert str(dataset / file) in message
    assert fragment in message


def test_missing_folder():
    with pytest.raises(MeasuredDataError, match="no such dataset folder"):
        load_dataset("/nonexistent/dataset")


def test_measured_data_error_is_a_value_error():
    assert issubclass(MeasuredDataError, ValueError)


def test_amplitude_labels_are_numbered_in_order_of_appearance(dataset):
    text = GOOD_METADATA
    for old, new in (
        ("drop_height_m: 0.05}", "amplitude: low}"),
        ("drop_height_m: 0.10", "amplitude: high"),
    ):
        text = text.replace(old, new)
    (dataset / METADATA_FILE).write_text(text)
    meta = read_metadata(dataset)
    assert [s.amplitude for s in meta.shots] == [0, 1, 0]
    assert all(math.isnan(s.impact_speed_m_s) for s in meta.shots)


def test_integer_amplitudes_are_kept_and_tolerate_trailing_blank_lines(dataset):
    text = GOOD_METADATA.replace("drop_height_m: 0.05", "amplitude: 3").replace(
        "drop_height_m: 0.10", "amplitude: 7"
    )
    (dataset / METADATA_FILE).write_text(text)
    (dataset / "s0.csv").write_text("\n".join(_good_csv()) + "\n\n\n")
    table = load_dataset(dataset)
    assert list(table.groupby("shot")["amplitude"].first()) == [3, 7, 3]


def test_unquoted_exponent_interval_is_accepted(dataset):
    # PyYAML reads 1e-6 (no dot) as a string; the loader accepts it as the number.
    (dataset / METADATA_FILE).write_text(GOOD_METADATA.replace("1.0e-6", "1e-6"))
    assert read_metadata(dataset).sampling_interval_s == 1e-6


def test_write_metadata_refuses_bad_metadata(tmp_path):
    with pytest.raises(MeasuredDataError, match="missing keys"):
        write_metadata(tmp_path, {"N": 3})
    assert not (tmp_path / METADATA_FILE).exists()


def test_writers_leave_no_temporary_files(tmp_path):
    write_shot_csv(tmp_path / "x.csv", np.arange(3) * 1e-6, np.zeros((1, 3)), (1,))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.csv"]
    assert (tmp_path / "x.csv").read_text().splitlines()[:2] == ["t_s,bead1_V", "0,0"]


def test_example_copy_with_a_missing_shot_file(tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(EXAMPLE, copy)
    (copy / "shot_0004.csv").unlink()
    with pytest.raises(MeasuredDataError, match=r"metadata.yaml line \d+: shots\[4\].file"):
        load_dataset(copy)


def test_loaded_table_is_independent_of_the_folder_spelling():
    a = load_dataset(EXAMPLE)
    b = load_dataset(str(EXAMPLE) + "/")
    pd.testing.assert_frame_equal(a, b)


# ----------------------------------------------------------------------------- schema


def test_metadata_schema_is_the_package_file_and_linked_from_the_workflow():
    root = Path(__file__).resolve().parents[1]
    shipped = root / "src" / "chain" / "apparatus" / "metadata.schema.yaml"
    linked = root / "workflow" / "schemas" / "metadata.schema.yaml"
    assert linked.resolve() == shipped.resolve()
    from importlib import resources

    from chain.apparatus.metadata import SCHEMA_FILE, metadata_validator

    assert resources.files("chain.apparatus").joinpath(SCHEMA_FILE).read_text() == (
        shipped.read_text()
    )
    assert metadata_validator().schema["required"] == [
        "N",
        "sensor_beads",
        "sensitivity_mV_per_N",
        "sampling_interval_s",
        "shots",
    ]


def test_readme_example_metadata_follows_the_schema():
    """The metadata.yaml example of data/README.md is valid (the schema is the spec)."""
    from chain.apparatus.metadata import parse_metadata

    text = (Path(__file__).resolve().parents[1] / "data" / "README.md").read_text()
    block = text.split("```yaml\nformat: hertzchain-measured-traces/1", 1)[1].split("```", 1)[0]
    meta = parse_metadata(yaml.safe_load("format: hertzchain-measured-traces/1" + block))
    assert meta.samples == 2600 and meta.adc_range_V == 2.0 and meta.adc_bits == 12
    assert [s.amplitude for s in meta.shots] == [0, 0, 0, 1]


# ----------------------------------------------------------------------------- one parse


def test_load_reuses_the_checked_samples_and_a_cached_verdict_reads_the_file(tmp_path):
    """A load parses each shot file once (the check's samples); after a cache hit the
    file is read by the loader: the same table either way."""
    from chain.apparatus.dataset_check import check_dataset
    from chain.apparatus.shot_files import read_shot_csv

    check = check_dataset(EXAMPLE, keep_data=True)
    assert sorted(check.data) == list(range(len(check.metadata.shots)))
    time, volts = read_shot_csv(EXAMPLE / check.metadata.shots[0].file, check.metadata.sensor_beads)
    np.testing.assert_array_equal(check.data[0][:, 0], time)
    np.testing.assert_array_equal(check.data[0][:, 1:].T, volts)
    assert check_dataset(EXAMPLE).data == {}  # not kept unless asked
    fresh = load_dataset(EXAMPLE)
    load_dataset(EXAMPLE, cache_dir=tmp_path)  # fills the cache
    assert check_dataset(EXAMPLE, cache_dir=tmp_path, keep_data=True).data == {}
    pd.testing.assert_frame_equal(load_dataset(EXAMPLE, cache_dir=tmp_path), fresh)


def test_shot_file_text_is_that_of_numpy_savetxt(tmp_path):
    """write_shot_csv formats all rows at once: the bytes of np.savetxt with its formats."""
    import io

    rng = np.random.default_rng(5)
    time = 3.3e-7 + 1e-6 * np.arange(50)
    volts = np.round(rng.normal(0, 2, (2, 50)), 3)
    volts[0, :3] = -0.0
    volts[1, 4] = 1.234567891e-9
    write_shot_csv(tmp_path / "a.csv", time, volts, (9, 17))
    expected = io.StringIO()
    np.savetxt(
        expected,
        np.column_stack([time, (volts + 0.0).T]),
        fmt=["%.10g", "%.7g", "%.7g"],
        delimiter=",",
        header="t_s,bead9_V,bead17_V",
        comments="",
    )
    assert (tmp_path / "a.csv").read_text() == expected.getvalue()
    assert "-0," not in expected.getvalue()
