"""Joint positions read whole: the CSV, ``.npy`` and C3D recordings of world positions per frame, in one array.

Many recordings have joint positions without rotations or a hierarchy (a Kinect, a pose estimator, a marker export);
their readers are :mod:`toolkit.recordings.csv_positions`, :mod:`toolkit.recordings.npy_positions` and
:mod:`toolkit.recordings.c3d_markers`, opened by :func:`toolkit.recordings.open_recording` a block at a time.
:func:`read_positions` reads one whole, for a caller that wants every frame at once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from toolkit.errors import ConfigError
from toolkit.recordings import open_recording

__all__ = ["JointPositions", "read_positions", "SUFFIXES"]

SUFFIXES = (".csv", ".npy", ".c3d")
"""The recordings of joint positions (the formats of :data:`toolkit.recordings.READERS` without a hierarchy)."""


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
    """Read a joint-position recording (``.csv``, ``.npy`` or ``.c3d``, by its suffix) whole.

    Parameters
    ----------
    path : path
        The file.
    names : sequence of str, optional
        A ``.npy`` file's joint names (required there: one per joint of the array). For a CSV or C3D file, the
        joints to read, in this order (default: every joint of the file, in its order).
    fps : float, optional
        Frames per second, in ``(0, MAX_FPS]``; required for ``.npy`` and for a CSV without a ``time`` column,
        ignored for a CSV with one and for a C3D file.

    Returns
    -------
    JointPositions
        The rows :func:`toolkit.recordings.open_recording` gives, in one array.

    Raises
    ------
    ConfigError
        Anything wrong with the file or the arguments, naming the file (and line and column in a CSV).
    """
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise ConfigError(f"unknown file type {path.suffix or '(no suffix)'!r}", file=path,
                          expected="a joint-position file", available=SUFFIXES)
    with open_recording(path, names=names, fps=fps) as recording:
        blocks = list(recording.blocks())
    positions = np.concatenate(blocks) if blocks else np.empty((0, len(recording.names), 3))
    return JointPositions(recording.names, positions, float(recording.fps), recording.source)
