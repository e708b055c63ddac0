"""Joint-position recordings (toolkit/positions.py): CSV and .npy files written here, read back; every error path."""

from __future__ import annotations

import os
import tracemalloc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from toolkit.recordings import csv_positions as pos
from toolkit.errors import ConfigError
from toolkit.recordings.recording import MAX_COORDINATE
from toolkit.recordings import MAX_FPS, open_recording
from toolkit.recordings.positions import JointPositions, read_positions
from toolkit.recordings.recording import MAX_JOINTS

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])



def iter_position_blocks(path, **kwargs):
    """The recording's header (its names and rate) and its blocks, as open_recording gives them."""
    recording = open_recording(path, **kwargs)
    return recording, recording.blocks()

def write(path, text, encoding="utf-8"):
    path.write_text(text, encoding=encoding, newline="")
    return path


def csv_text(names, positions, *, times=None, delimiter=",", axis_style="_x", extra=True, order=None, quote=False,
             missing="", line_end="\n"):
    """A CSV of ``positions`` (F, J, 3): columns per joint and axis in ``order`` (a permutation of J*3), an ignored
    text column, an optional time column first. NaN is written as ``missing``."""
    sep, upper = axis_style[0], axis_style[1].isupper()
    header = [f"{n}{sep}{a.upper() if upper else a}" for n in names for a in "xyz"]
    order = list(range(len(header))) if order is None else list(order)
    cells = [header[k] for k in order] + (["label"] if extra else [])
    if times is not None:
        cells = ["time", *cells]
    q = '"' if quote else ""
    lines = [delimiter.join(cells)]
    flat = positions.reshape(len(positions), len(names) * 3)
    for f, row in enumerate(flat):
        values = [missing if np.isnan(v) else f"{q}{v!r}{q}" for v in row[order].tolist()]
        if extra:
            values.append("a b")
        if times is not None:
            values = [repr(float(times[f])), *values]
        lines.append(delimiter.join(values))
    return line_end.join(lines) + line_end


names_st = st.lists(st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,6}", fullmatch=True), min_size=1, max_size=5, unique=True)
value_st = st.one_of(st.floats(-MAX_COORDINATE, MAX_COORDINATE, width=64), st.just(float("nan")))
"""Every coordinate a recording gives as seen (beyond ``MAX_COORDINATE`` in size it is read as not seen)."""


@st.composite
def recordings(draw, max_frames=25):
    names = draw(names_st)
    n = draw(st.integers(0, max_frames))
    flat = draw(st.lists(value_st, min_size=n * len(names) * 3, max_size=n * len(names) * 3))
    positions = np.array(flat, dtype=float).reshape(n, len(names), 3)
    return names, positions


def same(a, b):
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


# -- CSV round trips --------------------------------------------------------------------------------


@SETTINGS
@given(rec=recordings(), data=st.data(), delimiter=st.sampled_from([",", ";", "\t"]),
       axis_style=st.sampled_from(["_x", "_X", ".x", ".X"]), bom=st.booleans(), timed=st.booleans(),
       frames=st.integers(1, 9), crlf=st.booleans())
def test_csv_round_trip(tmp_path, rec, data, delimiter, axis_style, bom, timed, frames, crlf):
    names, positions = rec
    order = data.draw(st.permutations(range(len(names) * 3)))
    fps = data.draw(st.sampled_from([24.0, 30.0, 59.94, 120.0]))
    times = 1.5 + np.arange(len(positions)) / fps if timed else None
    text = csv_text(names, positions, times=times, delimiter=delimiter, axis_style=axis_style, order=order,
                    missing=data.draw(st.sampled_from(["", "nan", "NaN", " "])), line_end="\r\n" if crlf else "\n")
    path = write(tmp_path / "rec.csv", ("\ufeff" if bom else "") + text)
    given_fps = None if timed and len(positions) >= 2 else 25.0
    got = read_positions(path, fps=given_fps)
    # joints in the order of their first column
    first = {}
    for k in order:
        first.setdefault(names[k // 3], len(first))
    assert got.names == tuple(sorted(names, key=first.get))
    index = [names.index(n) for n in got.names]
    assert same(got.positions, positions[:, index])
    assert got.fps == pytest.approx(fps if given_fps is None else given_fps, rel=1e-9)
    assert got.source == str(path)
    header, blocks = iter_position_blocks(path, fps=given_fps, frames=frames)
    parts = list(blocks)
    assert header.names == got.names and header.fps == got.fps and len(header.names) == len(names)
    assert all(1 <= len(p) <= frames for p in parts)
    assert same(np.concatenate(parts) if parts else np.empty((0, len(header.names), 3)), got.positions)


@SETTINGS
@given(rec=recordings(), delimiter=st.sampled_from([",", ";", "\t"]), frames=st.integers(1, 7))
def test_quoted_cells_read_the_same_as_bare_ones(tmp_path, rec, delimiter, frames):
    """Quotes send a block through the field-by-field reader; it must give what numpy.loadtxt gives."""
    names, positions = rec
    bare = read_positions(write(tmp_path / "bare.csv", csv_text(names, positions, delimiter=delimiter)), fps=30)
    header, blocks = iter_position_blocks(write(tmp_path / "quoted.csv", csv_text(names, positions,
                                          delimiter=delimiter, quote=True)), fps=30, frames=frames)
    assert header.names == bare.names
    parts = list(blocks)
    assert same(np.concatenate(parts) if parts else np.empty((0, len(header.names), 3)), bare.positions)
    assert same(bare.positions, positions)


def test_plain_blocks_with_missing_values_are_read_by_numpy_not_field_by_field(tmp_path, monkeypatch):
    def refuse(*args):
        raise AssertionError("a plain block went field by field")

    monkeypatch.setattr(pos, "parse_rows", refuse)
    text = "a_x,a_y,a_z,b_x,b_y,b_z,note\n,1,,,2,nan,\n1,2,3,4,5,6,x\n,,,,,,\n"
    got = read_positions(write(tmp_path / "plain.csv", text), fps=30)
    nan = np.nan
    assert same(got.positions, np.array([[[nan, 1, nan], [nan, 2, nan]], [[1, 2, 3], [4, 5, 6]],
                                         [[nan, nan, nan], [nan, nan, nan]]]))


def test_names_select_and_order_the_joints_of_a_csv(tmp_path):
    positions = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    path = write(tmp_path / "a.csv", csv_text(["hip", "head", "hand"], positions))
    got = read_positions(path, names=["hand", "hip"], fps=30)
    assert got.names == ("hand", "hip")
    assert same(got.positions, positions[:, [2, 0]])
    with pytest.raises(ConfigError, match=r"a.csv:1: joint 'foot' is not in the file.*available: hip, head, hand"):
        read_positions(path, names=["hand", "foot"], fps=30)


def test_missing_values_are_nan_and_other_columns_are_ignored(tmp_path):
    text = "frame;head_x;head_y;head_z;note\n1;1;;3;ok\n2; nan ;NaN;inf;x y z\n3;-inf;  ;2e0;\n"
    got = read_positions(write(tmp_path / "semi.csv", text), fps=10)
    assert got.names == ("head",)
    assert same(got.positions[:, 0], np.array([[1, np.nan, 3], [np.nan, np.nan, np.nan], [np.nan, np.nan, 2.0]]))


def test_byte_order_mark_tab_delimiter_and_blank_lines(tmp_path):
    text = "\ufeffTime\tA.x\tA.y\tA.z\n0\t1\t2\t3\n\n   \n0.5\t4\t5\t6\n"
    got = read_positions(write(tmp_path / "tab.csv", text))
    assert got.names == ("A",) and got.fps == 2.0
    assert same(got.positions, np.array([[[1.0, 2, 3]], [[4.0, 5, 6]]]))


def test_time_column_gives_the_rate_from_the_span_and_wins_over_fps(tmp_path):
    steps = [0.01, 0.0105, 0.0095, 0.01, 0.012]  # jitter within TIME_TOLERANCE of the median
    times = np.concatenate([[0.0], np.cumsum(steps)])
    text = "time,j_x,j_y,j_z\n" + "".join(f"{float(t)!r},0,0,0\n" for t in times)
    got = read_positions(write(tmp_path / "t.csv", text), fps=30)
    assert got.fps == pytest.approx(5 / 0.052)


@pytest.mark.parametrize("fmt", ["%.6g", "%.3f"])
def test_rounded_times_give_the_true_rate(tmp_path, fmt):
    """Times of a 120 fps recording rounded to 1 ms: steps of 8 and 9 ms (a median step would say 125 fps)."""
    text = "time,j_x,j_y,j_z\n" + "".join(f"{fmt % (100 + k / 120)},0,0,0\n" for k in range(1201))
    assert read_positions(write(tmp_path / "t.csv", text)).fps == pytest.approx(120, rel=1e-4)


def test_header_only_gives_no_frames(tmp_path):
    got = read_positions(write(tmp_path / "h.csv", "a_x,a_y,a_z\n"), fps=50)
    assert got.positions.shape == (0, 1, 3) and got.fps == 50
    # a time column with fewer than two rows cannot give the rate: fps is used, and required
    timed = write(tmp_path / "one.csv", "time,a_x,a_y,a_z\n0,1,2,3\n")
    assert read_positions(timed, fps=12).fps == 12
    with pytest.raises(ConfigError, match=r"one.csv: no frame rate: the time column has fewer than 2 rows; "
                                          r"expected a frame rate: give `fps` in the profile's \[profile\] table "
                                          r"or --fps"):
        read_positions(timed)


# -- CSV errors -------------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "message"), [
    ("head_x,head_y,hand_x,hand_y,hand_z\n", r"bad.csv:1: joint 'head' has no z column; expected the columns "
                                             r"head_x, head_y and head_z; available: head_x, head_y"),
    ("time,a,b\n", r"bad.csv:1: no joint columns in the header; expected columns JOINT_x.*available: time, a, b"),
    ("a_x,a_y,a_z,a.x\n", r"bad.csv:1:13: columns 'a_x' and 'a.x' both name x of joint 'a'"),
    ("a_x,a_y,a_z,A_x,A_y,a_Z\n", r"bad.csv:1:21: columns 'a_z' and 'a_Z' both name z of joint 'a'"),
    ("time,a_x,a_y,a_z,TIME\n", r"bad.csv:1:18: two time columns \('time' and 'TIME'\)"),
    ("", r"bad.csv:1: no header line"),
    ("\n1,2,3\n", r"bad.csv:1: the header line is empty"),
    ("a_x,a_y,a_z\n1,2,3\n1,2,x\n", r"bad.csv:3:5: found 'x' in column 'a_z'; expected a number, or an empty cell "
                                   r"or nan for a missing value"),
    ("a_x,a_y,a_z\n1,2,3\n\n1, 2..5 ,3\n", r"bad.csv:4:3: found '2..5' in column 'a_y'"),
    ("a_x,a_y,a_z\n1,2,1_0\n", r"bad.csv:2:5: found '1_0' in column 'a_z'"),
    ('a_x,"a_y",a_z\n1,"2,5",3\n', r"bad.csv:2:3: found '2,5' in column 'a_y'"),
    ("a_x;a_y;a_z\n1,5;2;3\n", r"bad.csv:2:1: found '1,5' in column 'a_x'"),
    ("a_x,a_y,a_z\n1,2,3\n1,2\n", r"bad.csv:3:1: 2 fields; expected 3 fields separated by commas, as in the header"),
    ("a_x,a_y,a_z\n1,2,3,4\n", r"bad.csv:2:1: 4 fields; expected 3 fields"),
    ('a_x,a_y,a_z\n1,"2,3\n', r"bad.csv:2:1: malformed CSV line"),
])
def test_csv_errors(tmp_path, text, message):
    with pytest.raises(ConfigError, match=message):
        read_positions(write(tmp_path / "bad.csv", text), fps=30)


@pytest.mark.parametrize(("times", "message"), [
    ([0, 0.1, 0.2, 0.35, 0.45], r"t.csv:6:1: irregular timing: a step of 0.15 s from the row before is 1.5 frames; "
                                r"expected steps of whole frames of 0.1 s"),
    ([0, 0.1, 0.1, 0.2], r"t.csv:5:1: time 0.1 s does not increase from 0.1 s"),
    ([0, 0.1, 0.05, 0.2], r"t.csv:5:1: time 0.05 s does not increase"),
    ([0, 0.1, "", 0.3], r"t.csv:5:1: time missing in column 'time'"),
    ([0, 0.1, "inf", 0.3], r"t.csv:5:1: time inf in column 'time'"),
    ([0, 0.1, "x", 0.3], r"t.csv:5:1: found 'x' in column 'time'; expected a time in seconds"),
    ([0, 1e-5, 2e-5], r"t.csv:4:1: the time column's step of 1e-05 s is 100000 frames per second; expected "
                      r"times in seconds at a frame rate in \(0, 10000\] Hz"),
])
def test_time_errors_name_the_row(tmp_path, times, message):
    text = "time,a_x,a_y,a_z\n\n" + "".join(f"{t},1,2,3\n" for t in times)
    with pytest.raises(ConfigError, match=message):
        read_positions(write(tmp_path / "t.csv", text), fps=30)
    with pytest.raises(ConfigError, match=message):
        iter_position_blocks(tmp_path / "t.csv", frames=2)  # raised at once: the rate is needed for the header


def test_no_frame_rate(tmp_path):
    path = write(tmp_path / "n.csv", "a_x,a_y,a_z\n1,2,3\n")
    with pytest.raises(ConfigError, match=r"n.csv: no frame rate: the file has no 'time' column; expected a frame "
                                          r"rate: give `fps` in the profile's \[profile\] table or --fps"):
        read_positions(path)


@pytest.mark.parametrize("fps", [0, -1, float("nan"), float("inf"), MAX_FPS * 1.01, True, "30"])
def test_frame_rate_argument_is_bounded(tmp_path, fps):
    path = write(tmp_path / "n.csv", "a_x,a_y,a_z\n1,2,3\n")
    with pytest.raises(ConfigError, match=r"n.csv: the frame rate given is .*; expected a"):
        read_positions(path, fps=fps)
    assert read_positions(path, fps=MAX_FPS).fps == MAX_FPS


def test_a_bad_row_is_raised_from_the_iterator_when_its_block_is_read(tmp_path):
    text = "a_x,a_y,a_z\n" + "1,2,3\n" * 5 + "1,?,3\n"
    header, blocks = iter_position_blocks(write(tmp_path / "late.csv", text), fps=30, frames=2)
    assert header.names == ("a",)
    assert next(blocks).shape == (2, 1, 3) and next(blocks).shape == (2, 1, 3)
    with pytest.raises(ConfigError, match=r"late.csv:7:3: found '\?' in column 'a_y'"):
        next(blocks)


def test_bounds_on_lines_columns_and_joints(tmp_path, monkeypatch):
    monkeypatch.setattr(pos, "MAX_LINE_CHARS", 40)
    path = write(tmp_path / "long.csv", "a_x,a_y,a_z\n1,2,3\n" + "1," * 30 + "\n")
    with pytest.raises(ConfigError, match=r"long.csv:3:1: line longer than 40 characters"):
        read_positions(path, fps=30)
    write(path, "a_x,a_y,a_z\n" + "1.0000000000000000000000000000000000,2,3\n")  # 40 characters and a line break
    assert read_positions(path, fps=30).positions.shape == (1, 1, 3)
    monkeypatch.setattr(pos, "MAX_LINE_CHARS", 1 << 20)
    monkeypatch.setattr(pos, "MAX_COLUMNS", 5)
    with pytest.raises(ConfigError, match=r"wide.csv:1: 6 columns; expected at most 5 columns"):
        read_positions(write(tmp_path / "wide.csv", "a_x,a_y,a_z,b_x,b_y,b_z\n"), fps=30)
    monkeypatch.setattr(pos, "MAX_COLUMNS", 100)
    monkeypatch.setattr(pos, "MAX_JOINTS", 1)
    with pytest.raises(ConfigError, match=r"wide.csv:1: 2 joints; expected at most 1 joints"):
        read_positions(tmp_path / "wide.csv", fps=30)


CELL = st.text(alphabet=st.sampled_from(list("0123456789.eE+-_ naifNIFx\"")), max_size=8)


@settings(max_examples=300, deadline=None)
@given(rows=st.lists(st.lists(CELL, min_size=3, max_size=3), min_size=1, max_size=4))
def test_numpy_reads_a_block_as_the_field_by_field_reader_does(rows):
    """Whenever numpy.loadtxt reads a block, the reference reader reads the same values from it."""
    layout = pos._Layout(pos.Path("f.csv"), "a_x,a_y,a_z\n", ",", ("a_x", "a_y", "a_z"), ("a",), (0, 1, 2), None)
    lines = [",".join(r) + "\n" for r in rows]
    fast = pos._parse_fast(lines, layout, layout.columns)
    try:
        slow = pos.parse_rows(lines, list(range(2, 2 + len(lines))), layout, layout.columns)
    except ConfigError:
        assert fast is None
    else:
        assert fast is None or same(fast, slow)


@settings(max_examples=500, deadline=None)
@given(line=st.text(alphabet=st.sampled_from(list('ab1 ,;"\t')), max_size=20), delimiter=st.sampled_from([",", ";"]))
def test_error_columns_are_where_the_csv_module_starts_each_field(line, delimiter):
    try:
        fields = pos._split(line, delimiter, pos.Path("f.csv"), 1)
    except ConfigError:
        return
    starts = pos._field_starts(line, delimiter)
    assert len(starts) == max(len(fields), 1)
    for start, field in zip(starts, fields):
        raw = line[start - 1:]
        assert raw.startswith((field, '"'))


TOKENS = st.sampled_from(["a_x", "a_y", "b.X", "time", "1", "-2.5e3", "nan", "", " ", "x", '"', ",", ";", "\t",
                          "\n", "\r\n", "\ufeff", "0.1", "1e-9", "inf", "\x00", "\xe9"])
BASE = "time,a_x,a_y,a_z,b.X,b.Y,b.Z,note\n" + "".join(f"{k / 30!r},1,2,3,,5,6e0,n\n" for k in range(6))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 3), TOKENS), max_size=6),
       fps=st.sampled_from([None, 30.0]), frames=st.integers(1, 4))
def test_mutated_csv_is_read_or_a_config_error(tmp_path, edits, fps, frames):
    """A valid CSV with tokens inserted or characters replaced: every outcome is a JointPositions or a ConfigError
    (never another exception), and the blocks agree with the whole read."""
    text = BASE
    for where, cut, token in edits:
        at = int(where * len(text))
        text = text[:at] + token + text[at + cut:]
    path = write(tmp_path / "fuzz.csv", text)
    try:
        got = read_positions(path, fps=fps)
    except ConfigError:
        return
    assert got.positions.shape[1:] == (len(got.names), 3) and 0 < got.fps <= MAX_FPS
    header, blocks = iter_position_blocks(path, fps=fps, frames=frames)
    parts = list(blocks)
    assert same(np.concatenate(parts) if parts else np.empty((0, len(header.names), 3)), got.positions)


# -- .npy -------------------------------------------------------------------------------------------


@SETTINGS
@given(rec=recordings(), dtype=st.sampled_from(["<f8", ">f8", "<f4", "<i4", "<u2"]), fortran=st.booleans(),
       frames=st.integers(1, 9))
def test_npy_round_trip(tmp_path, rec, dtype, fortran, frames):
    names, positions = rec
    if dtype[1] in "iu":
        positions = np.nan_to_num(np.clip(positions, 0, 1000)).round()
    elif dtype == "<f4":
        positions = np.clip(positions, -1e30, 1e30)
    array = positions.astype(dtype)
    path = tmp_path / "rec.npy"
    np.save(path, np.asfortranarray(array) if fortran else array)
    got = read_positions(path, names=names, fps=60)
    assert isinstance(got, JointPositions) and got.names == tuple(names) and got.fps == 60
    assert got.positions.dtype == np.float64
    assert same(got.positions, array.astype(float))
    header, blocks = iter_position_blocks(path, names=names, fps=60, frames=frames)
    parts = list(blocks)
    assert len(header.names) == len(names) and all(1 <= len(p) <= frames for p in parts)
    assert same(np.concatenate(parts) if parts else np.empty((0, len(header.names), 3)), got.positions)


def test_npy_infinite_values_are_missing(tmp_path):
    np.save(tmp_path / "i.npy", np.array([[[1.0, np.inf, -np.inf]]]))
    assert same(read_positions(tmp_path / "i.npy", names=["a"], fps=1).positions, np.array([[[1.0, np.nan, np.nan]]]))


def test_npy_errors(tmp_path):
    np.save(tmp_path / "flat.npy", np.zeros((4, 6)))
    with pytest.raises(ConfigError, match=r"flat.npy: array of shape \(4, 6\); expected a NumPy array \(frames, "
                                          r"joints, 3\) of numbers"):
        read_positions(tmp_path / "flat.npy", names=["a", "b"], fps=30)
    np.save(tmp_path / "obj.npy", np.array([[["a", 1, 2]]], dtype=object), allow_pickle=True)
    with pytest.raises(ConfigError, match=r"obj.npy: array of dtype object \(Python objects, which likeme never "):
        read_positions(tmp_path / "obj.npy", names=["a"], fps=30)
    np.save(tmp_path / "text.npy", np.array([[["a", "b", "c"]]]))
    with pytest.raises(ConfigError, match=r"text.npy: array of dtype <U1"):
        read_positions(tmp_path / "text.npy", names=["a"], fps=30)
    np.save(tmp_path / "ok.npy", np.zeros((5, 2, 3)))
    with pytest.raises(ConfigError, match=r"ok.npy: 1 joint names for an array of 2 joints; expected 2 joint names"):
        read_positions(tmp_path / "ok.npy", names=["a"], fps=30)
    with pytest.raises(ConfigError, match=r"ok.npy: a .npy file has no joint names; expected the names of its 2 "):
        read_positions(tmp_path / "ok.npy", fps=30)
    with pytest.raises(ConfigError, match=r"ok.npy: a .npy file has no frame rate; expected a frame rate: give `fps`"):
        read_positions(tmp_path / "ok.npy", names=["a", "b"])
    with pytest.raises(ConfigError, match=r"ok.npy: joint 'a' named twice"):
        read_positions(tmp_path / "ok.npy", names=["a", "a"], fps=30)
    with pytest.raises(ConfigError, match=r"ok.npy: joint names 'ab'; expected a list of joint names"):
        read_positions(tmp_path / "ok.npy", names="ab", fps=30)
    data = (tmp_path / "ok.npy").read_bytes()
    (tmp_path / "short.npy").write_bytes(data[:-8])
    with pytest.raises(ConfigError, match=r"short.npy: a header declaring the shape \(5, 2, 3\) of float64 \(240 "
                                          r"bytes\) on 232 bytes of data"):
        read_positions(tmp_path / "short.npy", names=["a", "b"], fps=30)
    np.savez(tmp_path / "z.npz", a=np.zeros((1, 1, 3)))
    (tmp_path / "z.npz").rename(tmp_path / "z.npy")
    with pytest.raises(ConfigError, match=r"z.npy: a .npz archive \(zip\), not a .npy array"):
        read_positions(tmp_path / "z.npy", names=["a"], fps=30)
    (tmp_path / "empty.npy").write_bytes(b"")
    with pytest.raises(ConfigError, match=r"empty.npy: not a .npy file \(no NumPy header\)"):
        read_positions(tmp_path / "empty.npy", names=["a"], fps=30)


def _npy_header(shape, *, version=(1, 0), descr="<f8", data=b"\0" * 264):
    """A .npy file's bytes: a header declaring ``shape`` (any numbers: hostile ones too), then ``data``."""
    import io

    header = {"descr": descr, "fortran_order": False, "shape": shape}
    buffer = io.BytesIO()
    (np.lib.format.write_array_header_1_0 if version == (1, 0) else np.lib.format.write_array_header_2_0)(buffer, header)
    return buffer.getvalue() + data


@pytest.mark.parametrize("name, content, message", [
    ("big63.npy", _npy_header((2**63, 11, 3)), r"a header declaring the shape \(9223372036854775808, 11, 3\) of "
                                              r"float64 \(2,434,970,217,729,660,813,312 bytes\) on 264 bytes of data"),
    ("big30.npy", _npy_header((10**30, 11, 3)), r"the shape \(a number of 31 digits, 11, 3\) of float64"),
    ("negative.npy", _npy_header((-1, 11, 3)), r"a header declaring the shape \(-1, 11, 3\); expected a NumPy array"),
    ("gib4.npy", _npy_header((2**32 // 264, 11, 3), version=(2, 0)), r"\(4,294,967,160 bytes\) on 264 bytes of data"),
    ("objects.npy", _npy_header((2, 11, 3), descr="|O"), r"array of dtype object \(Python objects"),
    ("text-shape.npy", _npy_header(("a", 11, 3)), r"not a readable .npy header \(shape is not valid: \('a', 11, 3\)"),
    ("npz.npy", None, r"a .npz archive \(zip\), not a .npy array"),
])
def test_a_hostile_npy_header_is_one_line_naming_the_file_and_nothing_is_mapped(tmp_path, name, content, message):
    """Shapes past any size, negative or not numbers, a header declaring gigabytes on a small file, an archive
    named .npy: each refused from the header, checked against the file's size, before any data is mapped; by the
    reader and by ``likeme validate`` (with and without a profile)."""
    from likeme.cli import main

    path = tmp_path / name
    if content is None:
        np.savez(tmp_path / "a.npz", a=np.zeros((2, 11, 3)))
        (tmp_path / "a.npz").rename(path)
    else:
        path.write_bytes(content)
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match=message) as info:
            read_positions(path, names=[f"j{k}" for k in range(11)], fps=30)
        assert tracemalloc.get_traced_memory()[1] < 2**20
    finally:
        tracemalloc.stop()
    assert str(info.value).startswith(str(path)) and "\n" not in str(info.value)
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main(["validate", "--fps", "30", str(path)])
    assert status == 1 and err.getvalue().count("\n") == 1, err.getvalue()
    assert err.getvalue().startswith(f"likeme: error: {path}: "), err.getvalue()


# -- files that are not regular files ---------------------------------------------------------------


def test_only_regular_files_are_read(tmp_path):
    (tmp_path / "dir.csv").mkdir()
    with pytest.raises(ConfigError, match=r"dir.csv: is a directory, not a file; expected a regular file"):
        read_positions(tmp_path / "dir.csv", fps=30)
    os.mkfifo(tmp_path / "fifo.csv")  # opening it would block until a writer comes: it must not be opened
    with pytest.raises(ConfigError, match=r"fifo.csv: is a FIFO \(named pipe\), not a file; expected a regular file"):
        iter_position_blocks(tmp_path / "fifo.csv", fps=30)
    (tmp_path / "zero.npy").symlink_to("/dev/zero")
    with pytest.raises(ConfigError, match=r"zero.npy: is a character device, not a file; expected a regular file"):
        read_positions(tmp_path / "zero.npy", names=["a"], fps=30)
    with pytest.raises(ConfigError, match=r"missing.csv: cannot read \(No such file or directory\)"):
        read_positions(tmp_path / "missing.csv", fps=30)
    with pytest.raises(ConfigError, match=r"x.txt: unknown file type '.txt'; expected a joint-position file; "
                                          r"available: .csv, .npy"):
        read_positions(tmp_path / "x.txt", fps=30)


# -- memory -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".csv", ".npy"])
def test_peak_memory_is_a_small_multiple_of_the_positions(tmp_path, suffix):
    """No per-value Python objects: reading 20,000 frames of 20 joints (9.6 MB of float64) peaks under twice that (the
    blocks and the array they are joined into) plus a few blocks of text (a block is at most about 1 Mi characters)."""
    rng = np.random.default_rng(0)
    positions = rng.normal(size=(20_000, 20, 3))
    names = [f"j{k}" for k in range(20)]
    path = tmp_path / f"big{suffix}"
    if suffix == ".npy":
        np.save(path, positions)
    else:
        write(path, csv_text(names, positions, extra=False))
    tracemalloc.start()
    try:
        got = read_positions(path, names=names if suffix == ".npy" else None, fps=120)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert same(got.positions, positions)
    assert peak < 2 * positions.nbytes + 8e6, f"peak {peak / 1e6:.1f} MB"


def test_the_documented_bounds_are_the_module_constants():
    doc = (pos.Path(__file__).resolve().parents[3] / "docs" / "formats.md").read_text()
    assert f"`MAX_FPS` = {MAX_FPS:,.0f}" in doc
    assert f"`MAX_COLUMNS` ({pos.MAX_COLUMNS:,})" in doc and f"`MAX_JOINTS` ({MAX_JOINTS:,})" in doc
    assert f"`TIME_TOLERANCE` ({pos.TIME_TOLERANCE:.0%})" in doc and pos.MAX_LINE_CHARS == 1 << 20


# -- C3D marker files ---------------------------------------------------------------------------------


def _write_c3d(path, labels, positions, fps=120.0):
    from plugins.bench.data import write_positions

    return write_positions(path, list(labels), positions, fps=fps)


@settings(max_examples=25, deadline=None)
@given(frames=st.integers(1, 40), joints=st.integers(1, 6), seed=st.integers(0, 2**16),
       fps=st.sampled_from([30.0, 60.0, 100.0, 120.0, 240.0]), block=st.integers(1, 50))
def test_a_c3d_file_round_trips_as_32_bit_floats_with_missing_points(tmp_path_factory, frames, joints, seed, fps, block):
    rng = np.random.default_rng(seed)
    positions = rng.normal(scale=2.0, size=(frames, joints, 3))
    positions[rng.random((frames, joints)) < 0.1] = np.nan  # not reconstructed in that frame
    labels = [f"M{j}" for j in range(joints)]
    path = _write_c3d(tmp_path_factory.mktemp("c3d") / "t.c3d", labels, positions, fps)
    got = read_positions(path)
    assert got.names == tuple(labels) and got.fps == pytest.approx(fps)
    np.testing.assert_allclose(got.positions, positions.astype(np.float32), equal_nan=True)
    header, blocks = iter_position_blocks(path, frames=block)
    parts = list(blocks)
    assert all(len(b) <= block for b in parts) and header.names == got.names
    np.testing.assert_array_equal(np.concatenate(parts), got.positions)


def test_c3d_names_select_and_order_points_and_repeated_labels_are_numbered(tmp_path):
    positions = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    path = _write_c3d(tmp_path / "m.c3d", ["Head", "Head", ""], positions)
    assert read_positions(path).names == ("Head", "Head#2", "point#3")
    got = read_positions(path, names=["point#3", "Head"])
    np.testing.assert_array_equal(got.positions, positions[:, [2, 0]])
    with pytest.raises(ConfigError, match=r"m.c3d: no point labelled 'Nose'; expected a point of this file; "
                                          r"available: Head, Head#2, point#3"):
        read_positions(path, names=["Nose"])


def test_a_broken_c3d_file_is_one_error_naming_it(tmp_path):
    good = _write_c3d(tmp_path / "good.c3d", ["A", "B"], np.zeros((30, 2, 3))).read_bytes()
    for name, data in (("zeros.c3d", b"\0" * 100), ("cut.c3d", good[:700]), ("empty.c3d", b"")):
        (tmp_path / name).write_bytes(data)
        with pytest.raises(ConfigError, match=rf"{name}: (not a readable C3D file \(.*\)|truncated: .*); expected a "
                                              r"(C3D|whole C3D)"):
            read_positions(tmp_path / name)
    fast = _write_c3d(tmp_path / "fast.c3d", ["A"], np.zeros((3, 1, 3)), fps=50_000.0)
    with pytest.raises(ConfigError, match=r"fast.c3d: POINT:RATE is 50000 frames per second; expected a frame rate"):
        read_positions(fast)
