"""A recording opened for reading, whatever its format: what every reader returns (:func:`toolkit.recordings.open_recording`).

The joint names and the frame rate are known as soon as a recording is opened (its header is read and checked
then); its frames follow a block at a time, so reading memory does not grow with the file. Positions are the
file's own: its units and axes, every joint it has (a BVH's end sites included), NaN where a value is missing. A
body profile (:mod:`toolkit.recordings.profile`) turns them into a body's parts in metres with +y up.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from numbers import Real
from pathlib import Path
from typing import Any

from toolkit.errors import ConfigError

__all__ = ["Recording", "BLOCK", "MAX_FPS", "MIN_FPS", "MAX_JOINTS", "MAX_COORDINATE", "FPS_HINT", "check_fps",
           "check_names", "shortened"]

BLOCK = 4096
"""Frames per block when a recording is read a block at a time (and a BVH's forward kinematics is run)."""

MAX_FPS = 10_000.0
"""The highest frame rate any reader accepts (Hz; a BVH's ``Frame Time`` of at least 0.1 ms, a CSV's time column,
``fps`` given): high-speed optical capture reaches a few kHz."""
MIN_FPS = 1.0 / 60.0
"""The lowest frame rate any reader accepts (a frame a minute: a BVH's ``Frame Time`` of at most 60 s, ``--fps``,
a profile's or a live stream's rate); lower ones only overflow the seconds every plugin turns into frames."""

FPS_RANGE = f"[1/60, {MAX_FPS:g}]"
"""The frame rates every reader accepts, as messages write them."""

MAX_JOINTS = 10_000
"""The most joints a recording of joint positions may have."""

FPS_HINT = "a frame rate: give `fps` in the profile's [profile] table or --fps"
"""What a recording without a frame rate of its own needs (a CSV without a time column, a ``.npy`` array)."""


class Recording:
    """A recording opened for reading (made by a reader's ``open_file``, through
    :func:`toolkit.recordings.open_recording`).

    Attributes
    ----------
    names : tuple of str
        The joints, in the order of the positions' second axis.
    fps : float or None
        Frames per second (``None`` only when opened with ``need_fps=False`` and the file has no rate of its own).
    source : str
        The file, for messages.
    kind : str
        The format in words, for people ("BVH", "CSV", "NumPy array", "C3D").
    n_frames : int or None
        The frames the file declares (a BVH header), else ``None``: known once read.
    parents : tuple of int or None
        The parent of each joint (-1 for a root), where the file has a hierarchy (a BVH).

    :meth:`blocks` yields the joint positions ``(k, J, 3)`` a block at a time, once; a problem in the frames raises
    (naming the file, line and column where it has them) when its block is read. A context manager: leaving it
    closes the file.
    """

    def __init__(self, names: Sequence[str], fps: float | None, source: str, kind: str, blocks: Iterator[Any],
                 close: Callable[[], Any] | None = None, *, n_frames: int | None = None,
                 parents: Sequence[int] | None = None) -> None:
        self.names, self.fps, self.source, self.kind = tuple(names), fps, str(source), kind
        self.n_frames = n_frames
        self.parents = None if parents is None else tuple(parents)
        self._blocks, self._close = blocks, close

    def blocks(self) -> Iterator[Any]:
        """The joint positions (k, J, 3), float64, in the file's units and axes, NaN where missing; once.

        A joint position with a coordinate beyond :data:`MAX_COORDINATE` in size is missing too (a bad frame is not
        visible): no body is a billion units across, and such a number (``1e308``) overflows the first sum or
        square the observer takes of it."""
        for block in self._blocks:
            yield _without_absurd(block)

    def close(self) -> None:
        if self._close is not None:
            self._close()

    def __enter__(self) -> Recording:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Recording({self.source!r}, {self.kind}, {len(self.names)} joints, {self.fps} fps)"


MAX_COORDINATE = 1e9
"""The largest size of a joint coordinate a recording gives (in its own units: a thousand kilometres in millimetres);
a position with a larger one is read as not seen in that frame (:meth:`Recording.blocks`)."""


def _without_absurd(block: Any) -> Any:
    """``block`` (k, J, 3) with every position that has a coordinate beyond :data:`MAX_COORDINATE` in size NaN."""
    import numpy as np

    block = np.asarray(block, dtype=float)
    with np.errstate(invalid="ignore"):
        absurd = (np.abs(block) > MAX_COORDINATE).any(axis=-1)
    if absurd.any():
        block = block.copy() if not block.flags.writeable else block
        block[absurd] = np.nan
    return block


def check_fps(fps: object, path: str | Path, what: str) -> float:
    """A frame rate in [:data:`MIN_FPS`, :data:`MAX_FPS`] Hz, or a :class:`ConfigError` naming ``path`` and
    ``what`` gave it."""
    if isinstance(fps, bool) or not isinstance(fps, Real):
        raise ConfigError(f"{what} is {fps!r}", file=path, expected=f"a number of frames per second in {FPS_RANGE}")
    try:
        value = float(fps)
    except OverflowError:  # an integer beyond a float
        value = math.inf
    if not (MIN_FPS <= value <= MAX_FPS):  # NaN fails too
        raise ConfigError(f"{what} is {value:g} frames per second", file=path,
                          expected=f"a frame rate in {FPS_RANGE} Hz")
    return value


def check_names(names: Sequence[str] | None, path: str | Path) -> tuple[str, ...] | None:
    """Joint names given by the caller: a list of unique, non-empty strings, at most :data:`MAX_JOINTS` of them."""
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


def shortened(items: Sequence[str], limit: int = 20) -> list[str]:
    """At most ``limit`` items of a list for a message, and how many were left out."""
    return list(items) if len(items) <= limit else [*items[:limit], f"... ({len(items) - limit} more)"]
