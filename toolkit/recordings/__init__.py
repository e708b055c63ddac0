"""Recordings: motion-capture files and live frames read into the toolkit, and the files benchmarks read.

One reader per format, each a module with an ``open_file`` function, behind one open function that chooses by the
file's suffix (:data:`READERS`, the only place a suffix is written; ``docs/formats.md`` describes each format):

=========  =============================================  ===================================================
suffix     reader                                         what it holds
=========  =============================================  ===================================================
``.bvh``   :mod:`toolkit.recordings.bvh`                  a joint hierarchy and channel values per frame
``.csv``   :mod:`toolkit.recordings.csv_positions`        joint positions per row, a time column or a rate
``.npy``   :mod:`toolkit.recordings.npy_positions`        an array (frames, joints, 3) of joint positions
``.c3d``   :mod:`toolkit.recordings.c3d_markers`          labelled 3D marker points
=========  =============================================  ===================================================

:func:`open_recording` gives a :class:`~toolkit.recordings.recording.Recording`: joint names and frame rate at once,
joint positions a block at a time. A body profile (:mod:`toolkit.recordings.profile`) maps a skeleton's joints to a
body's parts and reads any recording as a :class:`~toolkit.motion.Motion`. Frames piped in line by line are
:mod:`toolkit.recordings.live`; a BVH is written by :mod:`toolkit.recordings.bvh_writer`; a stream's true segments
(``NAME.segments.csv``) are :mod:`toolkit.recordings.segments`.

Importing this package loads no reader (nor numpy): each is imported when a file of its format is opened.
"""

from __future__ import annotations

from collections.abc import Sequence
from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING

from toolkit.errors import ConfigError
from toolkit.recordings.recording import BLOCK, MAX_FPS, Recording

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.recordings.profile import BodyProfile

__all__ = ["READERS", "SUFFIXES", "Recording", "open_recording", "recording_format", "is_recording", "BLOCK",
           "MAX_FPS", "BodyProfile", "load_profile"]

READERS: dict[str, tuple[str, str]] = {
    ".bvh": ("toolkit.recordings.bvh", "BVH"),
    ".csv": ("toolkit.recordings.csv_positions", "joint positions"),
    ".npy": ("toolkit.recordings.npy_positions", "NumPy array of joint positions"),
    ".c3d": ("toolkit.recordings.c3d_markers", "C3D markers"),
}
"""Each format's file name suffix (lower case; a file's suffix is compared in any case), its reader module and what
it holds, in words."""

SUFFIXES: tuple[str, ...] = tuple(READERS)
"""The suffixes of the recordings the toolkit reads: ``.bvh``, ``.csv``, ``.npy``, ``.c3d``."""


def recording_format(path: str | Path) -> str:
    """A recording's format, its suffix in lower case (one of :data:`SUFFIXES`); a :class:`ConfigError` listing the
    accepted suffixes for any other."""
    suffix = Path(path).suffix.lower()
    if suffix not in READERS:
        each = [f"{s} ({what})" for s, (_, what) in READERS.items()]
        formats = ", ".join(each[:-1]) + f" or {each[-1]}"
        raise ConfigError(f"unknown recording format {Path(path).suffix or '(no suffix)'!r}", file=path,
                          expected=f"a recording named by its format: {formats}", available=SUFFIXES)
    return suffix


def is_recording(path: str | Path) -> bool:
    """Whether a file is named as a recording (:data:`SUFFIXES`); a stream's ``NAME.segments.csv`` is not one."""
    from toolkit.recordings.segments import SUFFIX

    name = Path(path).name.lower()
    return Path(name).suffix in READERS and not name.endswith(SUFFIX)


def open_recording(path: str | Path, *, names: Sequence[str] | None = None, fps: float | None = None,
                   frames: int = BLOCK, need_fps: bool = True) -> Recording:
    """Open a recording by its suffix and read its header; its frames follow a block at a time.

    Parameters
    ----------
    path : path
        A regular file within the size cap (:mod:`toolkit.files`) named by its format.
    names : sequence of str, optional
        A ``.npy`` array's joint names (required there: it has none of its own); for a CSV or C3D file the joints
        to read, in this order (default: all). A BVH's joints are its hierarchy's.
    fps : float, optional
        The frame rate of a recording without one of its own (a CSV without a time column, a ``.npy`` array), in
        (0, :data:`MAX_FPS`]; a BVH's Frame Time, a CSV's time column and a C3D's rate win over it.
    frames : int
        The most frames per block.
    need_fps : bool
        With ``False``, a recording with no rate of its own and none given opens with ``fps = None`` instead of
        failing (``likeme profile`` proposes a profile without one).

    Raises
    ------
    ConfigError
        Naming the file (and line and column where the format has them): an unknown format, a header the reader
        refuses, a missing frame rate.
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames must be a positive integer, not {frames!r}")
    module = import_module(READERS[recording_format(path)][0])
    return module.open_file(Path(path), names=names, fps=fps, frames=frames, need_fps=need_fps)


def __getattr__(name: str) -> object:
    """:class:`~toolkit.recordings.profile.BodyProfile` and :func:`~toolkit.recordings.profile.load_profile`,
    imported when first used (they need numpy)."""
    if name in ("BodyProfile", "load_profile"):
        return getattr(import_module("toolkit.recordings.profile"), name)
    raise AttributeError(f"module 'toolkit.recordings' has no attribute {name!r}")
