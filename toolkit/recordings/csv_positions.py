"""``.csv`` recordings: joint positions, one row per frame (``docs/formats.md``).

A header names ``JOINT_x``, ``JOINT_y``, ``JOINT_z`` for each joint (any order, other columns ignored; ``JOINT.x``
too); the frame rate comes from a ``time`` column in seconds, else from the ``fps`` the caller gives. Commas,
semicolons or tabs separate the fields (whichever the header has most of); double quotes are allowed.

Reading is bounded and streaming (issue 21): lines, columns and joints are bounded (:data:`MAX_LINE_CHARS`,
:data:`MAX_COLUMNS`, :data:`~toolkit.recordings.recording.MAX_JOINTS`); numbers are parsed into arrays a block of
lines at a time (``numpy.loadtxt``), never kept as one Python object per value. A line is scanned field by field
only to locate an error or when it has quotes. Every problem is a :class:`~toolkit.errors.ConfigError` naming the
file, line, column and the column's name. The header and row parsing serve lines on standard input too
(:mod:`toolkit.recordings.live`).
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file, open_regular
from toolkit.recordings.recording import (FPS_HINT, MAX_FPS, MAX_JOINTS, Recording, check_fps, check_names,
                                          shortened)

__all__ = ["open_file", "parse_header", "parse_rows", "MAX_COLUMNS", "MAX_LINE_CHARS", "TIME_TOLERANCE"]

MAX_COLUMNS = 100_000
"""The most columns a CSV header may have (joint coordinates and ignored columns together)."""

MAX_LINE_CHARS = 1 << 20
"""The longest CSV line accepted, in characters (without its line break)."""

TIME_TOLERANCE = 0.25
"""How far a step of a CSV time column may differ from the median step, as a fraction of the median step."""

_BLOCK_CHARS = 1 << 20  # a CSV block ends after about this many characters even if it has fewer than ``frames`` rows
_AXES = "xyz"
_COORDINATE = re.compile(r"^(?P<joint>.+)[_.](?P<axis>[xyzXYZ])$")


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
    return parse_header(line, path, names)


def parse_header(line: str, path: Path, names: tuple[str, ...] | None) -> _Layout:
    """A header line's layout (also the header of CSV lines on standard input, :mod:`toolkit.recordings.live`)."""
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
                          available=shortened(cells))
    if len(found) > MAX_JOINTS:
        raise ConfigError(f"{len(found)} joints", file=path, line=1, expected=f"at most {MAX_JOINTS} joints")
    joints = tuple(found)
    if names is not None:
        for name in names:
            if name not in found:
                raise ConfigError(f"joint {name!r} is not in the file", file=path, line=1,
                                  expected=f"the columns {name}_x, {name}_y and {name}_z", available=shortened(joints))
        joints = names
    columns = tuple(found[j][a] for j in joints for a in _AXES)
    return _Layout(path, line, delimiter, cells, joints, columns, time)


def open_file(path: Path, *, names: Sequence[str] | None = None, fps: float | None = None, frames: int = 4096,
              need_fps: bool = True) -> Recording:
    """A CSV of joint positions (:func:`toolkit.recordings.open_recording`): ``names`` the joints to read, in this
    order (default: every joint of the header); the frame rate from a ``time`` column, else ``fps``. A CSV with a time
    column is read twice: once for the times (to know the frame rate before the first block), once for the
    positions."""
    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        fps = check_fps(fps, path, "the frame rate given")
    layout = _layout(path, check_names(names, path))
    if layout.time is not None:
        measured = _rate_from_time(layout, frames)
        if measured is not None:
            fps = measured
    if fps is None and need_fps:
        raise ConfigError("no frame rate: the file has no 'time' column" if layout.time is None else
                          "no frame rate: the time column has fewer than 2 rows", file=path, expected=FPS_HINT)
    n_joints = len(layout.joints)

    def blocks() -> Iterator[np.ndarray]:
        for values, _ in _row_blocks(layout, layout.columns, frames):
            values[~np.isfinite(values)] = np.nan
            yield values.reshape(-1, n_joints, 3)

    return Recording(layout.joints, fps, str(path), "CSV", blocks())


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
                values = parse_rows(rows, numbers, layout, columns)
            yield values, (np.array(numbers, dtype=np.int64) if lines else None)


def _fill_empty(text: str, d: str) -> str:
    """``text`` (lines each ending in a line break) with ``nan`` in every empty field; a field of only spaces is left
    for :func:`parse_rows`."""
    if text.startswith(d):
        text = "nan" + text
    twice = d + d
    while twice in text:  # twice: in ",,," the second empty field starts where the first replacement ended
        text = text.replace(twice, d + "nan" + d)
    return text.replace("\n" + d, "\nnan" + d).replace(d + "\n", d + "nan\n")


def _parse_fast(rows: list[str], layout: _Layout, columns: Sequence[int]) -> np.ndarray | None:
    """The block's values by ``numpy.loadtxt``, or None when the block needs :func:`parse_rows` (quotes, a wrong
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


def parse_rows(rows: list[str], numbers: list[int], layout: _Layout, columns: Sequence[int]) -> np.ndarray:
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
