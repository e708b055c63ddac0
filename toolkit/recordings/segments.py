"""A stream's true segments: ``NAME.segments.csv`` beside the recording ``NAME.bvh`` (or ``.csv``, ``.npy``, ``.c3d``).

The file the segmentation benchmarks score against (``likeme bench make-data`` and ``likeme bench bandai`` write
it, ``docs/formats.md``): a header ``start_frame,end_frame,movement``, then one row per movement, frames counted
from the recording's first, the end exclusive. Blank lines are skipped; anything else that is not two frame numbers
``0 <= start < end`` and a movement name is a :class:`~toolkit.errors.ConfigError` naming the file and the line.
"""

from __future__ import annotations

import csv
from collections.abc import Iterable
from pathlib import Path

from toolkit.errors import ConfigError

__all__ = ["SUFFIX", "HEADER", "segments_of", "read_segments", "write_segments"]

SUFFIX = ".segments.csv"
"""What follows a recording's name (without its own suffix) in the name of its segments file."""

HEADER = ("start_frame", "end_frame", "movement")
"""The columns of a segments file, in order."""


def segments_of(recording: str | Path) -> Path:
    """The segments file of a recording: ``NAME.segments.csv`` beside ``NAME.bvh``."""
    recording = Path(recording)
    return recording.with_name(recording.stem + SUFFIX)


def read_segments(path: str | Path) -> list[tuple[int, int, str]]:
    """A ``NAME.segments.csv`` file: (start, end exclusive, movement) rows, checked, with the line of any error."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise ConfigError(f"cannot read ({exc.strerror})", file=path, expected="start_frame,end_frame,movement rows") from None
    if not lines or [h.strip() for h in lines[0].split(",")] != list(HEADER):
        raise ConfigError(f"found header {lines[0] if lines else ''!r}", file=path, line=1,
                          expected="the header start_frame,end_frame,movement")
    out = []
    for number, row in enumerate(csv.reader(lines[1:]), 2):
        if not row:
            continue
        try:
            start, end, label = int(row[0]), int(row[1]), row[2].strip()
        except (ValueError, IndexError):
            raise ConfigError(f"found {','.join(row)!r}", file=path, line=number,
                              expected="two frame numbers and a movement name") from None
        if not 0 <= start < end:
            raise ConfigError(f"segment {start}..{end}", file=path, line=number, expected="0 <= start_frame < end_frame")
        out.append((start, end, label))
    return out


def write_segments(path: str | Path, rows: Iterable[tuple[int, int, str]]) -> Path:
    """Write (start, end exclusive, movement) rows as a segments file that :func:`read_segments` reads back."""
    path = Path(path)
    path.write_text(",".join(HEADER) + "\n" + "".join(f"{a},{b},{m}\n" for a, b, m in rows), encoding="utf-8")
    return path
