"""``.c3d`` recordings: C3D motion-capture files of labelled 3D marker points (``docs/formats.md``).

Read with the maintained pure-Python ``c3d`` package: the file's 3D points are the joints, named by ``POINT:LABELS``,
at the file's ``POINT:RATE``; a point with a negative residual (not reconstructed in that frame) is missing.

The file is first checked against its own header (:func:`check_header`, the C3D.org specification's layout): the
header block's key byte, where the parameter section starts, its number of blocks and processor type, where the data
starts, and that the file holds every frame the header and parameters declare. A damaged header or a truncated file
is one error naming the file and the field, before the library reads it (a half-copied file was read silently,
short; a processor byte it does not know was an ``UnboundLocalError`` inside it).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, BinaryIO, TypeVar

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file, open_regular
from toolkit.recordings.recording import MAX_JOINTS, Recording, check_fps, check_names

__all__ = ["open_file", "check_header", "check_data", "BLOCK_BYTES", "PROCESSORS"]

BLOCK_BYTES = 512
"""A C3D file is made of 512-byte blocks, numbered from 1: the header is block 1."""
KEY = 0x50
"""The second byte of a C3D file (the header's key: 80)."""
PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}
"""The processor types a parameter section's fourth byte may name (how its numbers are stored)."""

T = TypeVar("T")


def open_file(path: Path, *, names: Sequence[str] | None = None, fps: float | None = None, frames: int = 4096,
              need_fps: bool = True) -> Recording:
    """A C3D file's 3D points as joints (:func:`toolkit.recordings.open_recording`): names from ``POINT:LABELS``
    (stripped; an empty or repeated label becomes ``LABEL#k``, k its point's number from 1), the rate from
    ``POINT:RATE`` (the file's own rate: ``fps`` given by the caller does not apply, as for BVH), a negative residual
    (``c3d``'s fourth column) missing. ``names`` selects and orders the points, as for a CSV."""
    import struct

    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        check_fps(fps, path, "the frame rate given")
    names = check_names(names, path)
    import c3d  # the maintained pure-Python reader (C3D.org format): imported where C3D is read

    expected = "a C3D motion-capture file with 3D points"
    broken = (ValueError, KeyError, IndexError, AssertionError, TypeError, EOFError, struct.error, OverflowError,
              MemoryError, UnicodeDecodeError)
    handle = open_regular(path, "C3D file", "motion")
    try:
        size = os.fstat(handle.fileno()).st_size
        parameters = check_header(handle.read(BLOCK_BYTES), handle, size, path)
        handle.seek(0)
        with warnings.catch_warnings():  # the library warns of what a marker file need not have (analog data)
            warnings.simplefilter("ignore")
            reader = c3d.Reader(handle)
            if reader.get("POINT:LABELS") is None:
                raise ConfigError("no POINT:LABELS parameter", file=path, expected=f"{expected}, labelled")
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
        fps = check_fps(rate, path, "POINT:RATE")
        try:
            check_data(reader, parameters, size, path)
        except broken as exc:
            raise ConfigError(f"not a readable C3D file ({type(exc).__name__}: {exc})", file=path,
                              expected=expected) from None
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

    return Recording(tuple(labels[c] for c in columns), fps, str(path), "C3D", blocks())


def check_header(head: bytes, handle: BinaryIO, size: int, path: Path) -> tuple[int, int]:
    """Check a C3D file's header block ``head`` (its first 512 bytes) and its parameter section's first four bytes
    (read from ``handle``) against the file's ``size``; return (the parameter section's first block, its number of
    blocks). A :class:`ConfigError` naming the file and the field otherwise (C3D.org, "The C3D file format": header
    word 1, parameter section bytes 3 and 4)."""
    expected = "a C3D motion-capture file with 3D points"
    if len(head) < BLOCK_BYTES:
        raise ConfigError(f"truncated: {size:,} bytes, shorter than the {BLOCK_BYTES}-byte C3D header", file=path,
                          expected=expected)
    first, key = head[0], head[1]
    if key != KEY:
        raise ConfigError(f"not a C3D file: its second byte is {key}", file=path,
                          expected=f"{expected} (second byte {KEY}, the C3D key)")
    if first < 2:
        raise ConfigError(f"the header puts the parameter section at block {first}", file=path,
                          expected="a parameter section after the header (block 2 or later)")
    if (first - 1) * BLOCK_BYTES + 4 > size:
        raise ConfigError(f"truncated: the parameter section at block {first} starts past the end of the file "
                          f"({size:,} bytes)", file=path, expected=expected)
    handle.seek((first - 1) * BLOCK_BYTES)
    _, _, blocks, processor = handle.read(4)
    if processor not in PROCESSORS:
        raise ConfigError(f"processor type {processor} in the parameter section", file=path,
                          expected="84 (Intel), 85 (DEC) or 86 (MIPS)")
    if blocks < 1:
        raise ConfigError("a parameter section of 0 blocks", file=path, expected="1 block or more of parameters")
    if (first - 1 + blocks) * BLOCK_BYTES > size:
        raise ConfigError(f"truncated: the parameter section (blocks {first} to {first + blocks - 1}) runs past the "
                          f"end of the file ({size:,} bytes)", file=path, expected=expected)
    return first, blocks


def check_data(reader: Any, parameters: tuple[int, int], size: int, path: Path) -> int:
    """Check where a parsed C3D file's data starts and that the file holds every frame it declares (its header's
    and parameters' first and last frame, ``reader``'s view of them); return the number of frames."""
    first, blocks = parameters
    start = int(reader.header.data_block)
    if start < first + blocks:
        raise ConfigError(f"the data starts at block {start}, inside the header or parameter section (blocks 1 to "
                          f"{first + blocks - 1})", file=path, expected=f"a data start block of {first + blocks} or later")
    frames = int(reader.last_frame) - int(reader.first_frame) + 1
    if frames < 1:
        raise ConfigError(f"no frames (first frame {reader.first_frame}, last frame {reader.last_frame})", file=path,
                          expected="a last frame at or after the first")
    is_float = reader.point_scale < 0
    per_frame = 4 * int(reader.point_used) * (4 if is_float else 2)
    if reader.analog_used:
        per_frame += int(reader.analog_used) * int(reader.analog_per_frame) * (4 if is_float else 2)
    held = max(0, size - (start - 1) * BLOCK_BYTES) // per_frame
    if held < frames:
        raise ConfigError(f"truncated: {frames:,} frames declared (frames {reader.first_frame} to "
                          f"{reader.last_frame}), the file holds {held:,}", file=path,
                          expected=f"a whole C3D file ({(start - 1) * BLOCK_BYTES + frames * per_frame:,} bytes or "
                                   f"more, this one has {size:,})")
    return frames


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
