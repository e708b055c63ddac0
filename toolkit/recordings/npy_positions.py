"""``.npy`` recordings: a NumPy array ``(frames, joints, 3)`` of joint positions (``docs/formats.md``).

The array has no joint names and no frame rate: the caller gives both (a body profile's ``joints`` and ``fps``, or
``--fps``). The file is memory-mapped (its header read, never unpickled) and copied a block at a time; a value that
is not finite is missing (NaN).
"""

from __future__ import annotations

import math
import os
import tokenize
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from toolkit.errors import ConfigError
from toolkit.files import check_regular_file
from toolkit.recordings.recording import FPS_HINT, MAX_JOINTS, Recording, check_fps, check_names

__all__ = ["open_file", "read_header", "NpyHeader"]

EXPECTED = "a NumPy array (frames, joints, 3) of numbers"


class NpyHeader(NamedTuple):
    """What a ``.npy`` file's header declares, checked against the file (:func:`read_header`)."""

    shape: tuple[int, ...]
    dtype: np.dtype
    fortran: bool
    offset: int


def read_header(path: Path) -> NpyHeader:
    """Read and check a ``.npy`` file's header without reading its data (nor unpickling anything).

    Refused, each a :class:`ConfigError` naming the file: a file that is not a ``.npy`` array (a ``.npz`` archive
    named ``.npy``, anything else), a header NumPy cannot read, a shape with a negative or non-integer size, a
    dtype of Python objects, and a header whose shape and dtype do not add up to the file's own size (a header
    declaring ``(2**63, 11, 3)``, ``(10**30, ...)`` or 4 GiB on a small file: the data is checked to be there
    before anything is mapped)."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(6)
            handle.seek(0)
            if head[:4] == b"PK\x03\x04":
                raise ConfigError("a .npz archive (zip), not a .npy array", file=path,
                                  expected=EXPECTED + " saved with numpy.save")
            if head != b"\x93NUMPY":
                raise ConfigError("not a .npy file (no NumPy header)", file=path, expected=EXPECTED)
            major, _minor = np.lib.format.read_magic(handle)
            read = {1: np.lib.format.read_array_header_1_0, 2: np.lib.format.read_array_header_2_0}.get(major)
            if read is None:
                raise ConfigError(f".npy format version {major}", file=path, expected=EXPECTED + " (version 1 or 2)")
            shape, fortran, dtype = read(handle)
            offset = handle.tell()
            size = os.fstat(handle.fileno()).st_size
    except ConfigError:
        raise
    except (ValueError, OSError, EOFError, OverflowError, TypeError, SyntaxError, KeyError, IndexError, AttributeError,
            RecursionError, tokenize.TokenError) as exc:  # what numpy's header parser raises on a damaged header
        problem = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"not a readable .npy header ({problem})", file=path, expected=EXPECTED) from None
    if dtype.hasobject:
        raise ConfigError(f"array of dtype {dtype} (Python objects, which likeme never unpickles)", file=path,
                          expected=EXPECTED)
    if not all(isinstance(n, int) and n >= 0 for n in shape):
        raise ConfigError(f"a header declaring the shape {shape}", file=path, expected=EXPECTED)
    declared = math.prod(shape) * dtype.itemsize
    if declared != size - offset:
        raise ConfigError(f"a header declaring the shape {_shape(shape)} of {dtype} ({declared:,} bytes) on "
                          f"{size - offset:,} bytes of data", file=path,
                          expected=EXPECTED + " whose header matches its data (a whole, undamaged file)")
    return NpyHeader(tuple(shape), dtype, bool(fortran), offset)


def _shape(shape: tuple[int, ...]) -> str:
    """A shape for a message, each size at most 20 digits written out."""
    sizes = [str(n) if n < 10**20 else f"a number of {len(str(n))} digits" for n in shape]
    return "(" + ", ".join(sizes) + ("," if len(sizes) == 1 else "") + ")"


def open_file(path: Path, *, names: Sequence[str] | None = None, fps: float | None = None, frames: int = 4096,
              need_fps: bool = True) -> Recording:
    """A ``.npy`` array of joint positions (:func:`toolkit.recordings.open_recording`): ``names`` are its joints'
    names (required), ``fps`` its frame rate (required unless ``need_fps`` is false)."""
    check_regular_file(path, "recording of joint positions", "motion")
    if fps is not None:
        fps = check_fps(fps, path, "the frame rate given")
    names = check_names(names, path)
    expected = EXPECTED
    header = read_header(path)
    if header.dtype.kind not in "fiu":
        raise ConfigError(f"array of dtype {header.dtype}", file=path, expected=expected)
    if len(header.shape) != 3 or header.shape[2] != 3:
        raise ConfigError(f"array of shape {_shape(header.shape)}", file=path, expected=expected)
    n_frames, n_joints = header.shape[0], header.shape[1]
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
    try:  # the header was checked against the file's size: the data is all there
        array = np.memmap(path, dtype=header.dtype, mode="r", offset=header.offset, shape=header.shape,
                          order="F" if header.fortran else "C") if n_frames else np.empty(header.shape)
    except (ValueError, OSError) as exc:
        raise ConfigError(f"cannot map the array ({exc})", file=path, expected=expected) from None

    def blocks() -> Iterator[np.ndarray]:
        for start in range(0, n_frames, frames):
            block = np.array(array[start:start + frames], dtype=float)
            block[~np.isfinite(block)] = np.nan
            yield block

    return Recording(names, fps, str(path), "NumPy array", blocks())
