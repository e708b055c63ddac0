"""Joint-position recordings: CSV tables, NumPy ``.npy`` arrays and C3D marker files of world positions per frame.

Many recordings have joint positions without rotations or a hierarchy (a Kinect, a pose estimator, a marker
export). This module reads them as :class:`JointPositions`: joint names, positions ``(F, J, 3)`` in the file's own
units and axes (a body profile converts them, as for BVH), NaN where a value is missing, and a frame rate.
``docs/formats.md`` describes both formats exactly:

- **CSV**: one row per frame; a header naming ``JOINT_x``, ``JOINT_y``, ``JOINT_z`` for each joint (any order, other
  columns ignored); the frame rate from a ``time`` column in seconds, else from the ``fps`` argument.
- **.npy**: an array ``(frames, joints, 3)`` of numbers; the joint names and the frame rate come from the caller.
- **.c3d**: a C3D motion-capture file (read with the maintained ``c3d`` package): its 3D points are the joints, named
  by ``POINT:LABELS``, at the file's ``POINT:RATE``; a point with a negative residual (not reconstructed in that
  frame) is missing.

Reading is bounded and streaming (issue 21): only regular files are opened; lines, columns, joints and the frame
rate are bounded (:data:`MAX_LINE_CHARS`, :data:`MAX_COLUMNS`, :data:`MAX_JOINTS`, :data:`MAX_FPS`); numbers are
parsed into arrays a block of lines at a time (``numpy.loadtxt``), never kept as one Python object per value, and
``.npy`` files are memory-mapped and copied a block at a time. A line is scanned field by field only to locate an
error or when it has quotes. Every problem is a :class:`~toolkit.errors.ConfigError` naming the file, and for a CSV
cell its line, column and the CSV column's name.
"""

from __future__ import annotations

import csv
import io
import re
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from numbers import Real
from pathlib import Path
from typing import TypeVar

import numpy as np

from toolkit.bvh import MAX_FPS
from toolkit.errors import ConfigError
from toolkit.files import check_regular_file, open_regular

__all__ = ["JointPositions", "read_positions", "iter_position_blocks", "SUFFIXES", "MAX_FPS", "MAX_JOINTS",
           "MAX_COLUMNS", "MAX_LINE_CHARS", "TIME_TOLERANCE"]

SUFFIXES = (".csv", ".npy", ".c3d")
"""File name suffixes this module reads (compared case-insensitively)."""

# Frame rates are accepted in ``(0, MAX_FPS]`` Hz, from a time column or the ``fps`` argument: the bound every
# reader of recordings shares (toolkit.bvh.MAX_FPS).

MAX_JOINTS = 10_000
"""The most joints a recording may have."""

MAX_COLUMNS = 100_000
"""The most columns a CSV header may have (joint coordinates and ignored columns together)."""

MAX_LINE_CHARS = 1 << 20
"""The longest CSV line accepted, in characters (without its line break)."""

TIME_TOLERANCE = 0.25
"""How far a step of a CSV time column may differ from the median step, as a fraction of the median step."""

_BLOCK_CHARS = 1 << 20  # a CSV block ends after about this many characters even if it has fewer than ``frames`` rows
_FPS_HINT = "a frame rate: give `fps` in the profile's [profile] table or --fps"
_AXES = "xyz"
T = TypeVar("T")
_COORDINATE = re.compile(r"^(?P<joint>.+)[_.](?P<axis>[xyzXYZ])$")


@dataclass(frozen=True, eq=False)
class JointPositions:
    """Joint positions read from a recording.

    Attributes
    ----------
    names : tuple of str
        The joint names, in the file's column order (a CSV) or as given (a ``.npy`` file, or ``names=``).
    positions : ndarray, shape (F, J, 3)
        World positions in the file's units and axes, float64; NaN where a value is missing (empty, ``nan`` or
        infinite), which the toolkit treats as not visible.
    fps : float
        Frames per second.
    source : str
        The file name, for messages.
    """

    names: tuple[str, ...]
    positions: np.ndarray
    fps: float
    source: str

    @property
    def n_frames(self) -> int:
        return int(self.positions.shape[0])


def read_positions(path: str | Path, *, names: Sequence[str] | None = None,
                   fps: float | None = None) -> JointPositions:
    """Read a joint-position recording (``.csv`` or ``.npy``, by its suffix) whole.

    Parameters
    ----------
    path : path
        The file.
    names : sequence of str, optional
        A ``.npy`` file's joint names (required there: one per joint of the array). For a CSV file, the joints to
        read, in this order (default: every joint of the header, in column order).
    fps : float, optional
        Frames per second, in ``(0, MAX_FPS]``; required for ``.npy`` and for a CSV without a ``time`` column,
        ignored for a CSV with one.

    Returns
    -------
    JointPositions
        The same rows :func:`iter_position_blocks` yields, in one array.

    Raises
    ------
    ConfigError
        Anything wrong with the file or the arguments, naming the file (and line and column in a CSV).
    """
    header, blocks = iter_position_blocks(path, names=names, fps=fps)
    parts = list(blocks)
    positions = np.concatenate(parts) if parts else header.positions
    return replace(header, positions=positions)


def iter_position_blocks(path: str | Path, *, names: Sequence[str] | None = None, fps: float | None = None,
                         frames: int = 4096) -> tuple[JointPositions, Iterator[np.ndarray]]:
    """Read a joint-position recording a block of frames at a time.

    The header (joint names, frame rate) is read and checked at once: a problem there raises here. A problem in a
    data row raises from the iterator when its block is read. A CSV with a ``time`` column is read twice: once for
    the times (to know the frame rate before the first block), once for the positions.

    Parameters
    ----------
    path, names, fps
        As for :func:`read_positions`.
    frames : int
        The most frames per block (a CSV block also ends after about 1 Mi characters of text).

    Returns
    -------
    header : JointPositions
        Names, frame rate and source, with an empty ``(0, J, 3)`` positions array.
    blocks : iterator of ndarray, shape (n, J, 3)
        The frames in order, float64, NaN where a value is missing.
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames must be a positive integer, not {frames!r}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ConfigError(f"unknown file type {path.suffix or '(no suffix)'!r}", file=path,
                          expected="a joint-position file", available=SUFFIXES)
    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        fps = _check_fps(fps, path, "the frame rate given")
    names = _check_names(names, path)
    if suffix == ".npy":
        return _npy(path, names, fps, frames)
    if suffix == ".c3d":
        return _c3d(path, names, frames)
    return _csv(path, names, fps, frames)


# -- shared checks ----------------------------------------------------------------------------------


def _check_fps(fps: object, path: Path, what: str) -> float:
    if isinstance(fps, bool) or not isinstance(fps, Real):
        raise ConfigError(f"{what} is {fps!r}", file=path,
                          expected=f"a number of frames per second in (0, {MAX_FPS:g}]")
    value = float(fps)
    if not (0.0 < value <= MAX_FPS):  # NaN fails too
        raise ConfigError(f"{what} is {value:g} frames per second", file=path,
                          expected=f"a frame rate in (0, {MAX_FPS:g}] Hz")
    return value


def _check_names(names: Sequence[str] | None, path: Path) -> tuple[str, ...] | None:
    if names is None:
        return None
    if isinstance(names, str) or not isinstance(names, Sequence):
        raise ConfigError(f"joint names {names!r}", file=path, expected="a list of joint names")
    if not names:
        raise ConfigError("no joint names", file=path, expected="a list of joint names")
    if len(names) > MAX_JOINTS:
        raise ConfigError(f"{len(names)} joint names", file=path, expected=f"at most {MAX_JOINTS} joints")
    seen: set[str] = set()
    for name in names:
        if not isinstance(name, str) or not name:
            raise ConfigError(f"joint name {name!r}", file=path, expected="a non-empty string")
        if name in seen:
            raise ConfigError(f"joint {name!r} named twice", file=path, expected="unique joint names")
        seen.add(name)
    return tuple(names)


def _short(items: Sequence[str], limit: int = 20) -> list[str]:
    """At most ``limit`` items of a list for a message, and how many were left out."""
    return list(items) if len(items) <= limit else [*items[:limit], f"... ({len(items) - limit} more)"]


# -- .npy -------------------------------------------------------------------------------------------


def _npy(path: Path, names: tuple[str, ...] | None, fps: float | None,
         frames: int) -> tuple[JointPositions, Iterator[np.ndarray]]:
    expected = "a NumPy array (frames, joints, 3) of numbers"
    try:
        array = np.lib.format.open_memmap(path, mode="r")  # reads the header only; never unpickles
    except (ValueError, OSError, EOFError) as exc:
        raise ConfigError(f"not a readable .npy array ({exc})", file=path, expected=expected) from None
    if array.dtype.kind not in "fiu":
        raise ConfigError(f"array of dtype {array.dtype}", file=path, expected=expected)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ConfigError(f"array of shape {array.shape}", file=path, expected=expected)
    n_frames, n_joints = int(array.shape[0]), int(array.shape[1])
    if not 0 < n_joints <= MAX_JOINTS:
        raise ConfigError(f"{n_joints} joints", file=path, expected=f"between 1 and {MAX_JOINTS} joints")
    if names is None:
        raise ConfigError("a .npy file has no joint names", file=path,
                          expected=f"the names of its {n_joints} joints (the profile's joint list)")
    if len(names) != n_joints:
        raise ConfigError(f"{len(names)} joint names for an array of {n_joints} joints", file=path,
                          expected=f"{n_joints} joint names")
    if fps is None:
        raise ConfigError("a .npy file has no frame rate", file=path, expected=_FPS_HINT)
    header = JointPositions(names, np.empty((0, n_joints, 3)), fps, str(path))

    def blocks() -> Iterator[np.ndarray]:
        for start in range(0, n_frames, frames):
            block = np.array(array[start:start + frames], dtype=float)
            block[~np.isfinite(block)] = np.nan
            yield block

    return header, blocks()


# -- C3D --------------------------------------------------------------------------------------------


def _c3d(path: Path, names: tuple[str, ...] | None, frames: int) -> tuple[JointPositions, Iterator[np.ndarray]]:
    """A C3D file's 3D points as joints: names from ``POINT:LABELS`` (stripped; an empty or repeated label becomes
    ``LABEL#k``, k its point's number from 1), the rate from ``POINT:RATE`` (the file's own rate: ``fps`` given by the
    caller does not apply, as for BVH), a negative residual (``c3d``'s fourth column) missing. ``names`` selects and
    orders the points, as for a CSV."""
    import struct

    import c3d  # the maintained pure-Python reader (C3D.org format): imported where C3D is read

    expected = "a C3D motion-capture file with 3D points"
    broken = (ValueError, KeyError, IndexError, AssertionError, TypeError, EOFError, struct.error, OverflowError,
              MemoryError, UnicodeDecodeError)
    handle = open_regular(path, "C3D file", "motion")
    try:
        with warnings.catch_warnings():  # the library warns of what a marker file need not have (analog data)
            warnings.simplefilter("ignore")
            reader = c3d.Reader(handle)
            labels = [str(label).strip() for label in reader.point_labels]
            n_points, rate = int(reader.point_used), float(reader.point_rate)
    except broken as exc:
        handle.close()
        raise ConfigError(f"not a readable C3D file ({type(exc).__name__}: {exc})", file=path,
                          expected=expected) from None
    except BaseException:
        handle.close()
        raise
    try:
        if not 0 < n_points <= MAX_JOINTS:
            raise ConfigError(f"{n_points} 3D points", file=path, expected=f"between 1 and {MAX_JOINTS} points")
        fps = _check_fps(rate, path, "POINT:RATE")
        labels = (labels + [""] * n_points)[:n_points]
        seen: set[str] = set()
        for k, label in enumerate(labels):
            if not label or label in seen:
                label = f"{label or 'point'}#{k + 1}"
            labels[k] = label
            seen.add(label)
        if names is None:
            columns = list(range(n_points))
        else:
            missing = [n for n in names if n not in seen]
            if missing:
                raise ConfigError(f"no point labelled {missing[0]!r}", file=path, expected="a point of this file",
                                  available=labels)
            columns = [labels.index(n) for n in names]
    except BaseException:
        handle.close()
        raise
    header = JointPositions(tuple(labels[c] for c in columns), np.empty((0, len(columns), 3)), fps, str(path))

    def blocks() -> Iterator[np.ndarray]:
        rows: list[np.ndarray] = []
        try:
            for _, points, _ in _quiet(reader.read_frames(copy=True, check_nan=False)):
                points = np.asarray(points, dtype=float)
                xyz = points[columns, :3].copy()
                xyz[(points[columns, 3] < 0) | ~np.isfinite(xyz).all(axis=1)] = np.nan
                rows.append(xyz)
                if len(rows) == frames:
                    yield np.stack(rows)
                    rows = []
        except broken as exc:
            raise ConfigError(f"not a readable C3D file ({type(exc).__name__}: {exc})", file=path,
                              expected=expected) from None
        finally:
            handle.close()
        if rows:
            yield np.stack(rows)

    return header, blocks()


def _quiet(items: Iterator[T]) -> Iterator[T]:
    """``items`` advanced with warnings ignored (the C3D library warns of what a marker file need not have)."""
    while True:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                item = next(items)
            except StopIteration:
                return
        yield item


# -- CSV --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Layout:
    """What a CSV header says: the delimiter, the number of fields, the joints' and the time's columns."""

    source: Path
    header_line: str
    delimiter: str
    cells: tuple[str, ...]
    joints: tuple[str, ...]
    columns: tuple[int, ...]  # the field index of joint j's axis a at 3 j + a
    time: int | None

    def column_name(self, field: int) -> str:
        return self.cells[field]


def _read_line(f: io.TextIOBase, number: int, source: Path) -> str:
    """The next line (with its line break), or ``""`` at the end; a line longer than MAX_LINE_CHARS is an error."""
    line = f.readline(MAX_LINE_CHARS + 1)
    if len(line) > MAX_LINE_CHARS and not line.endswith("\n"):
        raise ConfigError(f"line longer than {MAX_LINE_CHARS} characters", file=source, line=number, column=1,
                          expected="one CSV row per line")
    return line


def _open(path: Path) -> io.TextIOWrapper:
    """The file as text, opened by :func:`toolkit.files.open_regular` (checked again on the open descriptor)."""
    # utf-8-sig drops a byte-order mark; undecodable bytes become U+FFFD and fail as a number where they matter
    return io.TextIOWrapper(open_regular(path, "recording of joint positions", "motion"), encoding="utf-8-sig",
                            errors="replace", newline=None)


def _detect_delimiter(line: str) -> str:
    """Comma, semicolon or tab: whichever the header line has most of (comma on a tie or when it has none)."""
    counts = {d: line.count(d) for d in (",", ";", "\t")}
    return max(counts, key=lambda d: (counts[d], d == ",", d == ";"))


def _split(line: str, delimiter: str, source: Path, number: int) -> list[str]:
    """One line's fields as the csv module reads them (double quotes allowed)."""
    try:
        return next(csv.reader([line.rstrip("\n")], delimiter=delimiter, strict=True), [])
    except csv.Error as exc:
        raise ConfigError(f"malformed CSV line ({exc})", file=source, line=number, column=1,
                          expected="fields separated by " + _delimiter_name(delimiter)) from None


def _delimiter_name(delimiter: str) -> str:
    return {",": "commas", ";": "semicolons", "\t": "tabs"}[delimiter]


def _field_starts(line: str, delimiter: str) -> list[int]:
    """The 1-based character column where each field of ``line`` starts, as the csv module splits it (a double quote
    opens a quoted field only as the field's first character; ``""`` inside one is a quote)."""
    starts, quoted, i = [1], False, 0
    while i < len(line):
        c = line[i]
        if quoted:
            if c == '"':
                if line.startswith('"', i + 1):
                    i += 1
                else:
                    quoted = False
        elif c == '"' and i == starts[-1] - 1:
            quoted = True
        elif c == delimiter:
            starts.append(i + 2)
        i += 1
    return starts


def _layout(path: Path, names: tuple[str, ...] | None) -> _Layout:
    with _open(path) as f:
        line = _read_line(f, 1, path)
    return _parse_header(line, path, names)


def _parse_header(line: str, path: Path, names: tuple[str, ...] | None) -> _Layout:
    """A header line's layout (also the header of CSV lines on standard input, :mod:`toolkit.live`)."""
    if not line.strip():
        raise ConfigError("no header line" if not line else "the header line is empty", file=path, line=1,
                          expected="a header naming the columns JOINT_x, JOINT_y, JOINT_z of each joint")
    delimiter = _detect_delimiter(line)
    cells = tuple(c.strip() for c in _split(line, delimiter, path, 1))
    if len(cells) > MAX_COLUMNS:
        raise ConfigError(f"{len(cells)} columns", file=path, line=1, expected=f"at most {MAX_COLUMNS} columns")
    starts = _field_starts(line, delimiter)
    found: dict[str, dict[str, int]] = {}  # joint -> axis -> field index, in order of first appearance
    time = None
    for k, cell in enumerate(cells):
        if cell.lower() == "time":
            if time is not None:
                raise ConfigError(f"two time columns ({cells[time]!r} and {cell!r})", file=path, line=1,
                                  column=starts[k], expected="one 'time' column")
            time = k
            continue
        m = _COORDINATE.match(cell)
        if not m:
            continue
        joint, axis = m["joint"], m["axis"].lower()
        axes = found.setdefault(joint, {})
        if axis in axes:
            raise ConfigError(f"columns {cells[axes[axis]]!r} and {cell!r} both name {axis} of joint {joint!r}",
                              file=path, line=1, column=starts[k], expected="one column per joint coordinate")
        axes[axis] = k
    for joint, axes in found.items():
        missing = [a for a in _AXES if a not in axes]
        if missing:
            raise ConfigError(f"joint {joint!r} has no {' or '.join(missing)} column", file=path, line=1,
                              expected=f"the columns {joint}_x, {joint}_y and {joint}_z",
                              available=[cells[k] for k in axes.values()])
    if not found:
        raise ConfigError("no joint columns in the header", file=path, line=1,
                          expected="columns JOINT_x, JOINT_y, JOINT_z for each joint (or JOINT.x ...)",
                          available=_short(cells))
    if len(found) > MAX_JOINTS:
        raise ConfigError(f"{len(found)} joints", file=path, line=1, expected=f"at most {MAX_JOINTS} joints")
    joints = tuple(found)
    if names is not None:
        for name in names:
            if name not in found:
                raise ConfigError(f"joint {name!r} is not in the file", file=path, line=1,
                                  expected=f"the columns {name}_x, {name}_y and {name}_z", available=_short(joints))
        joints = names
    columns = tuple(found[j][a] for j in joints for a in _AXES)
    return _Layout(path, line, delimiter, cells, joints, columns, time)


def _csv(path: Path, names: tuple[str, ...] | None, fps: float | None,
         frames: int) -> tuple[JointPositions, Iterator[np.ndarray]]:
    layout = _layout(path, names)
    if layout.time is not None:
        measured = _rate_from_time(layout, frames)
        if measured is not None:
            fps = measured
    if fps is None:
        raise ConfigError("no frame rate: the file has no 'time' column" if layout.time is None else
                          "no frame rate: the time column has fewer than 2 rows", file=path, expected=_FPS_HINT)
    n_joints = len(layout.joints)
    header = JointPositions(layout.joints, np.empty((0, n_joints, 3)), fps, str(path))

    def blocks() -> Iterator[np.ndarray]:
        for values, _ in _row_blocks(layout, layout.columns, frames):
            values[~np.isfinite(values)] = np.nan
            yield values.reshape(-1, n_joints, 3)

    return header, blocks()


def _rate_from_time(layout: _Layout, frames: int) -> float | None:
    """Frames per second from the time column (steps within TIME_TOLERANCE of the median step; the rate is the number
    of steps over the time they span), or None with fewer than two rows."""
    path, name = layout.source, layout.column_name(layout.time)
    chunks = list(_row_blocks(layout, (layout.time,), frames, lines=True))
    times = np.concatenate([v[:, 0] for v, _ in chunks]) if chunks else np.empty(0)
    lines = np.concatenate([n for _, n in chunks]) if chunks else np.empty(0, dtype=np.int64)
    del chunks
    column = _field_starts(layout.header_line, layout.delimiter)[layout.time]
    bad = np.flatnonzero(~np.isfinite(times))
    if bad.size:
        k = int(bad[0])
        raise ConfigError(f"time {'missing' if np.isnan(times[k]) else times[k]} in column {name!r}", file=path,
                          line=int(lines[k]), column=column, expected="a finite time in seconds on every row")
    if times.size < 2:
        return None
    steps = np.diff(times)
    back = np.flatnonzero(steps <= 0)
    if back.size:
        k = int(back[0]) + 1
        raise ConfigError(f"time {times[k]:.9g} s does not increase from {times[k - 1]:.9g} s", file=path,
                          line=int(lines[k]), column=column, expected=f"increasing times in column {name!r}")
    step = float(np.median(steps))
    off = np.flatnonzero(np.abs(steps - step) > TIME_TOLERANCE * step)
    if off.size:
        k = int(off[0]) + 1
        raise ConfigError(f"irregular timing: a step of {steps[k - 1]:.6g} s from the row before", file=path,
                          line=int(lines[k]), column=column,
                          expected=f"steps of {step:.6g} s (the median) within {TIME_TOLERANCE:.0%}; "
                                   "for a recording with dropped frames, drop the time column and give fps")
    # the rate from the mean step (the span over the steps), not the median: with times rounded to a few digits the
    # median is one of the rounded steps (%.6g times at 120 fps: steps of 0.008 and 0.009 s, median 0.008 s, 125 fps)
    rate = (times.size - 1) / float(times[-1] - times[0])
    if not rate <= MAX_FPS:
        raise ConfigError(f"the time column's median step of {step:.6g} s is {rate:.6g} frames per second",
                          file=path, line=int(lines[1]), column=column,
                          expected=f"times in seconds at a frame rate in (0, {MAX_FPS:g}] Hz")
    return rate


def _row_blocks(layout: _Layout, columns: Sequence[int], frames: int,
                lines: bool = False) -> Iterator[tuple[np.ndarray, np.ndarray | None]]:
    """The values of ``columns`` in blocks of at most ``frames`` data rows (blank lines skipped), with each row's
    line number when ``lines`` is set."""
    path, delimiter = layout.source, layout.delimiter
    blank = " \t\f\v\n".replace(delimiter, "")
    with _open(path) as f:
        number = 1
        if _read_line(f, 1, path) != layout.header_line:
            raise ConfigError("the header changed while the file was read", file=path, line=1)
        done = False
        while not done:
            rows, numbers, size = [], [], 0
            while len(rows) < frames and size < _BLOCK_CHARS:
                number += 1
                line = _read_line(f, number, path)
                if not line:
                    done = True
                    break
                if line.strip(blank):
                    rows.append(line)
                    numbers.append(number)
                    size += len(line)
            if not rows:
                return
            values = _parse_fast(rows, layout, columns)
            if values is None:
                values = _parse_slow(rows, numbers, layout, columns)
            yield values, (np.array(numbers, dtype=np.int64) if lines else None)


def _fill_empty(text: str, d: str) -> str:
    """``text`` (lines each ending in a line break) with ``nan`` in every empty field; a field of only spaces is left
    for :func:`_parse_slow`."""
    if text.startswith(d):
        text = "nan" + text
    twice = d + d
    while twice in text:  # twice: in ",,," the second empty field starts where the first replacement ended
        text = text.replace(twice, d + "nan" + d)
    return text.replace("\n" + d, "\nnan" + d).replace(d + "\n", d + "nan\n")


def _parse_fast(rows: list[str], layout: _Layout, columns: Sequence[int]) -> np.ndarray | None:
    """The block's values by ``numpy.loadtxt``, or None when the block needs :func:`_parse_slow` (quotes, a wrong
    number of fields, a cell loadtxt does not read)."""
    d, n = layout.delimiter, len(layout.cells) - 1
    if any(row.count(d) != n for row in rows):
        return None
    text = "".join(rows)
    if not text.endswith("\n"):
        text += "\n"
    if '"' in text:
        return None
    text = _fill_empty(text, d)
    try:
        return np.loadtxt(io.StringIO(text), delimiter=d, usecols=columns, dtype=float, comments=None, ndmin=2,
                          quotechar=None)
    except ValueError:
        return None


def _parse_slow(rows: list[str], numbers: list[int], layout: _Layout, columns: Sequence[int]) -> np.ndarray:
    """The block's values field by field: the reference for :func:`_parse_fast`, and where errors are located."""
    path, d = layout.source, layout.delimiter
    out = np.empty((len(rows), len(columns)))
    for i, (row, number) in enumerate(zip(rows, numbers)):
        fields = _split(row, d, path, number)
        if len(fields) != len(layout.cells):
            raise ConfigError(f"{len(fields)} fields", file=path, line=number, column=1,
                              expected=f"{len(layout.cells)} fields separated by {_delimiter_name(d)}, "
                                       "as in the header")
        for k, c in enumerate(columns):
            cell = fields[c].strip()
            if not cell:
                out[i, k] = np.nan
                continue
            try:
                if "_" in cell:
                    raise ValueError(cell)
                out[i, k] = float(cell)
            except ValueError:
                raise ConfigError(f"found {cell!r} in column {layout.column_name(c)!r}", file=path, line=number,
                                  column=_field_starts(row, d)[c],
                                  expected="a time in seconds" if c == layout.time else
                                  "a number, or an empty cell or nan for a missing value") from None
    return out
