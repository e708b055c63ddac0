"""``.csv`` recordings: joint positions, one row per frame (``docs/formats.md``).

A header names ``JOINT_x``, ``JOINT_y``, ``JOINT_z`` for each joint (any order, other columns ignored; ``JOINT.x``
too); the frame rate comes from a ``time`` column in seconds, else from the ``fps`` the caller gives. Commas,
semicolons or tabs separate the fields (whichever the header has most of); double quotes are allowed.

Tracker output as it comes (issue 37): a ``time`` column with dropped frames (steps of two or more frames) places
each row on the frame grid and leaves the frames between missing (NaN: not visible); a file whose first line is
numbers has no header, and its columns are x, y, z of each joint the caller names, in that order (a body
profile's ``joints``), after an optional time column.

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

__all__ = ["open_file", "has_header", "parse_header", "parse_rows", "frame_grid", "MAX_COLUMNS", "MAX_LINE_CHARS",
           "TIME_TOLERANCE"]

MAX_COLUMNS = 100_000
"""The most columns a CSV header may have (joint coordinates and ignored columns together)."""

MAX_LINE_CHARS = 1 << 20
"""The longest CSV line accepted, in characters (without its line break)."""

TIME_TOLERANCE = 0.25
"""How far a step of a CSV time column may be from a whole number of frames (one, or more where frames were
dropped), as a fraction of a frame."""

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
    header: bool = True  # False: the first line is a frame, and the cells are names made for messages

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
    if line.strip() and _is_frame(line):
        return _headerless(line, path, names)
    return parse_header(line, path, names)


def has_header(path: str | Path) -> bool:
    """Whether a CSV file's first line is a header (else it is a frame, and the joints must be named in column
    order: a body profile's ``joints``). A file that cannot be read counts as having one: reading it reports why."""
    try:
        with _open(Path(path)) as f:
            line = _read_line(f, 1, Path(path))
    except (ConfigError, OSError):
        return True
    return not (line.strip() and _is_frame(line))


def _is_frame(line: str) -> bool:
    """Whether a first line is a frame rather than a header: every field a number or a missing value (empty,
    ``nan``, infinite), at least one a number."""
    fields = [c.strip() for c in line.rstrip("\n").split(_detect_delimiter(line))]
    numbers = 0
    for cell in fields:
        if not cell:
            continue
        try:
            value = float(cell.strip('"'))
        except ValueError:
            return False
        numbers += bool(np.isfinite(value))
    return numbers > 0


def _headerless(line: str, path: Path, names: tuple[str, ...] | None) -> _Layout:
    """The layout of a CSV without a header: x, y, z of each of ``names`` in order, after a time column when the
    line has one field more."""
    delimiter = _detect_delimiter(line)
    n_fields = len(_split(line, delimiter, path, 1))
    if names is None:
        raise ConfigError("the file has no header (its first line is numbers)", file=path, line=1,
                          expected="a header naming the columns JOINT_x, JOINT_y, JOINT_z, or the joints in column "
                                   "order (a body profile's [profile] joints = [...])")
    if n_fields not in (3 * len(names), 3 * len(names) + 1):
        raise ConfigError(f"{n_fields} fields in a file without a header", file=path, line=1, column=1,
                          expected=f"x, y and z of each of the {len(names)} joints named, in order "
                                   f"({3 * len(names)} fields), or a time in seconds first ({3 * len(names) + 1})",
                          available=shortened(names))
    time = 0 if n_fields == 3 * len(names) + 1 else None
    cells = (("time",) if time is not None else ()) + tuple(f"{j}_{a}" for j in names for a in _AXES)
    first = 1 if time is not None else 0
    return _Layout(path, line, delimiter, cells, names, tuple(range(first, n_fields)), time, header=False)


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
    order (default: every joint of the header), or of a file without a header its joints in column order
    (required there); the frame rate from a ``time`` column, else ``fps``. A CSV with a time column is read twice:
    once for the times (to know the frame rate and the frame grid before the first block), once for the
    positions; rows after dropped frames are placed at their frames (:func:`frame_grid`), the frames between NaN."""
    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        fps = check_fps(fps, path, "the frame rate given")
    layout = _layout(path, check_names(names, path))
    grid = None  # each row's frame on the time grid, where frames were dropped
    if layout.time is not None:
        measured, grid = _rate_from_time(layout, frames)
        if measured is not None:
            fps = measured
    if fps is None and need_fps:
        raise ConfigError("no frame rate: the file has no 'time' column" if layout.time is None else
                          "no frame rate: the time column has fewer than 2 rows", file=path, expected=FPS_HINT)
    n_joints = len(layout.joints)

    def rows() -> Iterator[np.ndarray]:
        for values, _ in _row_blocks(layout, layout.columns, frames):
            values[~np.isfinite(values)] = np.nan
            yield values.reshape(-1, n_joints, 3)

    blocks = rows() if grid is None else _on_grid(rows(), grid, n_joints, frames)
    n_frames = None if grid is None else int(grid[-1]) + 1
    return Recording(layout.joints, fps, str(path), "CSV", blocks, n_frames=n_frames)


def _on_grid(rows: Iterator[np.ndarray], grid: np.ndarray, n_joints: int, frames: int) -> Iterator[np.ndarray]:
    """The rows' positions placed at their frames of ``grid`` (increasing, from 0), the frames between them NaN
    (not visible); blocks of at most ``frames`` frames."""
    done = 0  # frames yielded
    row = 0  # rows placed
    for block in rows:
        at = grid[row:row + len(block)]
        row += len(block)
        end = int(at[-1]) + 1
        for start in range(done, end, frames):
            stop = min(start + frames, end)
            out = np.full((stop - start, n_joints, 3), np.nan)
            inside = (at >= start) & (at < stop)
            out[at[inside] - start] = block[inside]
            yield out
        done = end


def _rate_from_time(layout: _Layout, frames: int) -> tuple[float | None, np.ndarray | None]:
    """Frames per second from the time column (:func:`frame_grid`: the rows' frames, the rate the number of frames
    over the time they span), or None with fewer than two rows; with each row's frame where frames were dropped."""
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
        return None, None
    try:
        grid, step = frame_grid(times)
    except _OffGrid as err:
        k = err.row
        expected = {"back": f"increasing times in column {name!r}",
                    "off": f"steps of whole frames of {err.step:.6g} s (one, or more where frames were dropped) "
                           f"within {TIME_TOLERANCE:.0%} of a frame",
                    "sparse": "at least as many rows as frames missing between them (a frame grid whose step is "
                              "the median step)"}[err.kind]
        raise ConfigError(err.problem, file=path, line=int(lines[k]), column=column, expected=expected) from None
    rate = 1.0 / step
    if not rate <= MAX_FPS:
        raise ConfigError(f"the time column's step of {step:.6g} s is {rate:.6g} frames per second",
                          file=path, line=int(lines[1]), column=column,
                          expected=f"times in seconds at a frame rate in (0, {MAX_FPS:g}] Hz")
    return rate, (grid if grid[-1] != times.size - 1 else None)


class _OffGrid(Exception):
    """Times that are not a frame grid: at ``row``, of ``kind`` back (not increasing), off (not a whole number of
    frames from the row before) or sparse (more frames missing than rows)."""

    def __init__(self, kind: str, row: int, problem: str, step: float = float("nan")) -> None:
        super().__init__(problem)
        self.kind, self.row, self.problem, self.step = kind, row, problem, step


def frame_grid(times: np.ndarray) -> tuple[np.ndarray, float]:
    """Place rows with ``times`` (seconds, increasing, at least two) on a grid of frames: (each row's frame from 0,
    the frame step in seconds).

    The frame step is guessed as the median step (most frames kept), else as the shortest step (more gaps than
    single steps), then made the mean of the steps within :data:`TIME_TOLERANCE` of the guess (the single steps:
    times rounded to 1 ms at 30 fps have steps of 33 and 34 ms, and a gap of a hundred frames must count a
    hundred); every step must be a whole number of frames within the tolerance, the frames of a longer step
    dropped. The step returned is the time from the first row to the last over the frames between them (not the
    median: rounded times at 120 fps have steps of 8 and 9 ms, whose median says 125 fps). At most as many frames
    may be missing as there are rows (a time column of a few rows spread over hours is no recording).

    Raises a private ``_OffGrid`` naming the row where the times stop being a grid.
    """
    steps = np.diff(times)
    back = np.flatnonzero(~(steps > 0))
    if back.size:
        k = int(back[0]) + 1
        raise _OffGrid("back", k, f"time {times[k]:.9g} s does not increase from {times[k - 1]:.9g} s")
    failed = None
    for guess in (float(np.median(steps)), float(np.min(steps))):  # most steps single; else the shortest step
        single = np.abs(steps - guess) <= TIME_TOLERANCE * guess
        step = float(np.mean(steps[single])) if single.any() else guess
        counts = np.rint(steps / step)
        off = np.flatnonzero((counts < 1) | (np.abs(steps / step - counts) > TIME_TOLERANCE))
        if not off.size:
            break
        if failed is None:  # the error names the row where the median step's grid fails
            k = int(off[0]) + 1
            failed = _OffGrid("off", k, f"irregular timing: a step of {steps[k - 1]:.6g} s from the row before is "
                                        f"{steps[k - 1] / step:.3g} frames", step)
    else:
        raise failed
    missing = float(np.sum(counts)) + 1 - times.size  # a float: a fuzzed gap may exceed any integer
    if missing > times.size:
        k = int(np.argmax(counts)) + 1
        raise _OffGrid("sparse", k, f"{missing:.6g} frames missing between {times.size} rows (the longest gap, "
                                    f"{counts[k - 1] - 1:.6g} frames, before this row)")
    grid = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    return grid, float(times[-1] - times[0]) / int(grid[-1])


def _row_blocks(layout: _Layout, columns: Sequence[int], frames: int,
                lines: bool = False) -> Iterator[tuple[np.ndarray, np.ndarray | None]]:
    """The values of ``columns`` in blocks of at most ``frames`` data rows (blank lines skipped), with each row's
    line number when ``lines`` is set."""
    path, delimiter = layout.source, layout.delimiter
    blank = " \t\f\v\n".replace(delimiter, "")
    with _open(path) as f:
        number = 1 if layout.header else 0
        if layout.header and _read_line(f, 1, path) != layout.header_line:
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
