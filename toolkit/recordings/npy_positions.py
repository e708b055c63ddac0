"""``.npy`` recordings: a NumPy array ``(frames, joints, 3)`` of joint positions (``docs/formats.md``).

The array has no joint names and no frame rate: the caller gives both (a body profile's ``joints`` and ``fps``, or
``--fps``). The file is memory-mapped (its header read, never unpickled) and copied a block at a time; a value that
is not finite is missing (NaN).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file
from toolkit.recordings.recording import FPS_HINT, MAX_JOINTS, Recording, check_fps, check_names

__all__ = ["open_file"]


def open_file(path: Path, *, names: Sequence[str] | None = None, fps: float | None = None, frames: int = 4096,
              need_fps: bool = True) -> Recording:
    """A ``.npy`` array of joint positions (:func:`toolkit.recordings.open_recording`): ``names`` are its joints'
    names (required), ``fps`` its frame rate (required unless ``need_fps`` is false)."""
    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        fps = check_fps(fps, path, "the frame rate given")
    names = check_names(names, path)
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
    if fps is None and need_fps:
        raise ConfigError("a .npy file has no frame rate", file=path, expected=FPS_HINT)

    def blocks() -> Iterator[np.ndarray]:
        for start in range(0, n_frames, frames):
            block = np.array(array[start:start + frames], dtype=float)
            block[~np.isfinite(block)] = np.nan
            yield block

    return Recording(names, fps, str(path), "NumPy array", blocks())
