"""``.c3d`` recordings: C3D motion-capture files of labelled 3D marker points (``docs/formats.md``).

Read with the maintained pure-Python ``c3d`` package: the file's 3D points are the joints, named by ``POINT:LABELS``,
at the file's ``POINT:RATE``; a point with a negative residual (not reconstructed in that frame) is missing.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file, open_regular
from toolkit.recordings.recording import MAX_JOINTS, Recording, check_fps, check_names

__all__ = ["open_file"]

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
        fps = check_fps(rate, path, "POINT:RATE")
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
