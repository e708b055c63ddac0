"""Body profiles: how a motion-capture skeleton becomes a likeme body.

A profile is a TOML file (``docs/conventions.md`` has the format) saying which
source joints are the tracked body parts, which part is the root, which parts
give the facing (a left/right pair and an optional forward marker, like the
paper's knees and nose), the source's up axis and its units. Reading a recording
through a profile gives a :class:`~toolkit.motion.Motion` of world positions in
metres with ``+y`` up, one column per tracked part, and the :class:`Body` to
perceive it with. Recordings are opened by their suffix
(:func:`toolkit.recordings.open_recording`, ``docs/formats.md``): BVH files, CSV
joint positions, ``.npy`` arrays and C3D markers; the optional ``fps`` key gives
the frame rate of files without one of their own, ``joints`` the joint names of a
``.npy`` array.

Example (the Bandai-Namco skeleton, ``characters/profiles/bandai-namco.toml``)::

    [profile]
    name = "bandai-namco"
    units = "centimetre"
    up = "+y"

    [parts]
    root = "Hips"
    head = "Head"
    ...

    [facing]
    left = "left_hip"
    right = "right_hip"
    forward = "left_toes"
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.body import Body
from toolkit.errors import ConfigError
from toolkit.files import check_regular_file
from toolkit.motion import Motion
from toolkit.params import finite_number
from toolkit.recordings import BLOCK, MAX_FPS, open_recording, recording_format
from toolkit.recordings.csv_positions import has_header
from toolkit.recordings.recording import FPS_RANGE, MIN_FPS
from toolkit.recordings.bvh import BVH

__all__ = ["BodyProfile", "MotionStream", "is_profile", "load_profile", "UNITS", "UP_AXES"]

UNITS: dict[str, float] = {"metre": 1.0, "meter": 1.0, "m": 1.0, "centimetre": 0.01, "centimeter": 0.01, "cm": 0.01,
                           "millimetre": 0.001, "millimeter": 0.001, "mm": 0.001, "inch": 0.0254, "in": 0.0254,
                           "foot": 0.3048, "ft": 0.3048}
"""Unit names a profile may give, in metres."""

UP_AXES: dict[str, np.ndarray] = {
    "+y": np.eye(3),
    "-y": np.diag([1.0, -1.0, -1.0]),
    "+z": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
    "-z": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
    "+x": np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
    "-x": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
}
"""Rotations taking a source whose up axis is the key to likeme's ``+y`` up (right-handed, proper rotations)."""

_PROFILE_KEYS = ("name", "description", "units", "up", "fps", "joints")
_TABLES = ("profile", "parts", "facing", "bones", "colours")


@dataclass(frozen=True)
class BodyProfile:
    """A mapping from a source skeleton's joints to a likeme body.

    Attributes
    ----------
    name : str
    body : Body
        The tracked parts (in the order of ``joints``), root, facing, bones, colours.
    joints : tuple of str
        The source joint of each part.
    scale : float
        Metres per source unit.
    up : str
        The source's up axis (``"+y"``, ``"+z"``...).
    file : Path or None
    fps : float or None
        The frame rate of recordings without one of their own (a CSV without a ``time`` column, a ``.npy`` array):
        the ``[profile]`` table's ``fps`` key. A ``fps`` argument of :meth:`read` and :meth:`stream` wins over it;
        a BVH's ``Frame Time`` and a CSV's ``time`` column win over both.
    array_joints : tuple of str or None
        The joints of a ``.npy`` array or a CSV without a header, in the file's order (the ``[profile]`` table's
        ``joints`` key); without it, such a file's joints are the mapped joints, in the order of ``[parts]`` (each
        once).
    """

    name: str
    body: Body
    joints: tuple[str, ...]
    scale: float = 1.0
    up: str = "+y"
    file: Path | None = None
    description: str = ""
    fps: float | None = None
    array_joints: tuple[str, ...] | None = None

    def _where(self, part: str) -> dict[str, Any]:
        from toolkit.config.toml import find_key_line

        key = ("parts", part)
        return {"file": self.file, "key": key, "line": find_key_line(self.file, key) if self.file else None}

    @property
    def npy_joints(self) -> tuple[str, ...]:
        """The joint names of a ``.npy`` array read through this profile: :attr:`array_joints`, else the mapped
        joints in the order of ``[parts]``, each once."""
        return self.array_joints if self.array_joints is not None else tuple(dict.fromkeys(self.joints))

    def check(self, recording: Any) -> list[str]:
        """Raise a :class:`ConfigError` naming any mapped joint the recording lacks (with the joints it has); return
        the joints left unmapped.

        ``recording`` has ``names`` (its joints) and ``source`` (its file name): a
        :class:`~toolkit.recordings.recording.Recording` or a :class:`~toolkit.recordings.bvh.BVH` (a header is enough).
        """
        names = list(recording.names)
        for part, joint in zip(self.body.parts, self.joints):
            if joint not in names:
                raise ConfigError(f"joint {joint!r} of part {part!r} is not in {recording.source}",
                                  **self._where(part), expected="a joint of the file", available=names)
        used = set(self.joints)
        return [n for n in names if n not in used]

    def convert(self, joint_positions: np.ndarray, names: list[str] | tuple[str, ...]) -> np.ndarray:
        """Source joint positions (F, J, 3) to part positions (F, P, 3) in metres, +y up."""
        index = [list(names).index(j) for j in self.joints]
        return (joint_positions[:, index] * self.scale) @ UP_AXES[self.up].T

    def motion(self, bvh: BVH) -> Motion:
        """The world positions of the tracked parts over a BVH file's frames."""
        self.check(bvh)
        return Motion(self.convert(bvh.positions(), bvh.names), bvh.fps, self.body.parts)

    def read(self, path: str | Path, fps: float | None = None) -> Motion:
        """Read a recording (by its suffix: :func:`toolkit.recordings.open_recording`) whole and return its motion
        through this profile.

        ``fps``: the frame rate of a recording without one of its own (a CSV without a ``time`` column, a ``.npy``
        array); it wins over the profile's ``fps`` and is ignored for a BVH file and a CSV with a time column.
        """
        with self.stream(path, fps=fps) as motion:
            blocks = [positions for positions, _ in motion]
        positions = np.concatenate(blocks) if blocks else np.empty((0, len(self.body.parts), 3))
        return Motion(positions, motion.fps, self.body.parts)

    def stream(self, path: str | Path, block: int | None = None, fps: float | None = None) -> MotionStream:
        """A recording's motion through this profile, ``block`` frames at a time (:class:`MotionStream`).

        ``block`` defaults to :data:`toolkit.recordings.BLOCK`; ``fps`` as for :meth:`read`. The header is read and
        checked against the profile at once (the joint names, the frame rate); the frames follow as they are
        iterated, a block at a time (for a BVH file with forward kinematics run per block), so the memory does not
        grow with the file. A bad value raises the error reading the whole file raises.
        """
        block = BLOCK if block is None else max(1, int(block))
        suffix = recording_format(path)  # an array, and a CSV without a header, have no names of their own
        names = self.npy_joints if suffix == ".npy" or (suffix == ".csv" and not has_header(path)) else None
        recording = open_recording(path, names=names, fps=fps if fps is not None else self.fps, frames=block)
        try:
            self.check(recording)
        except BaseException:
            recording.close()
            raise
        return MotionStream(self, recording.names, recording.fps, recording.blocks(), recording.close,
                            n_frames=recording.n_frames)


class MotionStream:
    """The blocks of a recording read through a profile (made by :meth:`BodyProfile.stream`).

    ``fps`` and ``parts`` are known before the first block; iterating yields ``(positions, visible)`` blocks,
    positions (k, P, 3) in metres with +y up and visibility (k, P), as :meth:`BodyProfile.read` would give them.
    ``n_frames`` is the file's frame count for a BVH file (from its header), for the other formats the number of
    frames read so far (all of them once iterated). A context manager: leaving it closes the file.
    """

    def __init__(self, profile: BodyProfile, names: Sequence[str], fps: float, blocks: Iterator[np.ndarray],
                 close: Callable[[], Any] | None = None, *, n_frames: int | None = None) -> None:
        self.profile, self.names, self._fps = profile, list(names), float(fps)
        self._blocks, self._close, self._n_frames, self._read = blocks, close, n_frames, 0

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def n_frames(self) -> int:
        return self._n_frames if self._n_frames is not None else self._read

    @property
    def parts(self) -> list[str]:
        return list(self.profile.body.parts)

    def __iter__(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        for values in self._blocks:
            positions = self.profile.convert(values, self.names)
            self._read += len(positions)
            yield positions, np.isfinite(positions).all(axis=-1)

    def close(self) -> None:
        if self._close is not None:
            self._close()

    def __enter__(self) -> MotionStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def is_profile(table: Mapping[str, Any]) -> bool:
    """Whether a parsed TOML table is a body profile (it has a ``[profile]`` or ``[parts]`` table, no ``[character]``)."""
    return "character" not in table and ("profile" in table or "parts" in table)


def load_profile(path: str | Path) -> BodyProfile:
    """Read a body profile TOML file; every problem is a :class:`ConfigError` naming the file, key and line."""
    from toolkit.character import check_body
    from toolkit.config.toml import find_key_line, read_toml

    path = check_regular_file(path, "body profile", "config")  # not a FIFO or /dev/zero, not a huge file
    table = read_toml(path)

    def fail(problem: str, key: tuple, **kw: Any) -> ConfigError:
        return ConfigError(problem, file=path, key=key, line=find_key_line(path, key), **kw)

    for name in table:
        if name not in _TABLES:
            raise fail(f"unknown table {name!r}", (name,), expected="a profile table", available=_TABLES)
    head = table.get("profile", {})
    if not isinstance(head, Mapping):
        raise fail("invalid", ("profile",), expected="a table")
    for key in head:
        if key not in _PROFILE_KEYS:
            raise fail(f"unknown key {key!r}", ("profile", key), expected="a profile key", available=_PROFILE_KEYS)
    units = head.get("units", "metre")
    if isinstance(units, str):
        if units not in UNITS:
            raise fail(f"unknown units {units!r}", ("profile", "units"), expected="a unit name or metres per unit",
                       available=UNITS)
        scale = UNITS[units]
    elif (finite_number(units) or 0.0) > 0:
        scale = float(units)
    else:
        raise fail(f"invalid units {repr(units)[:40]}", ("profile", "units"),
                   expected="a unit name or a positive number (finite: metres per unit)")
    up = head.get("up", "+y")
    if not isinstance(up, str):
        raise fail(f"wrong type {type(up).__name__} (value {up!r})", ("profile", "up"),
                   expected='one axis as a string, like up = "+z"', available=UP_AXES)
    if up not in UP_AXES:
        raise fail(f"unknown up axis {up!r}", ("profile", "up"), expected="an axis", available=UP_AXES)
    parts = table.get("parts")
    if not isinstance(parts, Mapping) or not parts:
        raise fail("missing or empty", ("parts",), expected='a table of part = "source joint"')
    for part, joint in parts.items():
        if not isinstance(joint, str) or not joint:
            raise fail(f"invalid joint {joint!r}", ("parts", part), expected="the name of a source joint")
    facing = table.get("facing", {})
    if not isinstance(facing, Mapping):
        raise fail(f"invalid facing {facing!r}", ("facing",), expected='a table with left, right and optional forward, behind')
    facing = dict(facing)
    if "root" not in facing and "root" not in parts:
        raise fail("no part named 'root'", ("parts",), expected="a part named root (or facing.root naming it)",
                   available=list(parts))
    root = facing.pop("root", "root")
    body_table = {"parts": list(parts), "root": root, "facing": facing,
                  "bones": table.get("bones", []), "colours": table.get("colours", {})}
    try:
        body = check_body(Body.from_config(body_table))
    except ConfigError as exc:
        key = exc.key if exc.key and exc.key[0] in ("bones", "colours") else ("facing", *exc.key[1:]) if exc.key and \
            exc.key[0] in ("facing", "root") else exc.key
        raise fail(exc.problem, key, expected=exc.expected, available=exc.available) from None
    fps = head.get("fps")
    if fps is not None:
        if isinstance(fps, bool) or not isinstance(fps, int | float) or not MIN_FPS <= fps <= MAX_FPS:  # and NaN
            raise fail(f"invalid fps {fps!r}", ("profile", "fps"),
                       expected=f"frames per second of recordings without a time of their own, a number in "
                                f"{FPS_RANGE}")
        fps = float(fps)
    array_joints = head.get("joints")
    if array_joints is not None:
        if not isinstance(array_joints, list) or not array_joints or \
                not all(isinstance(j, str) and j for j in array_joints):
            raise fail(f"invalid joints {array_joints!r}", ("profile", "joints"),
                       expected="a list naming the joints of a .npy array in order, like joints = [\"Hips\", ...]")
        twice = sorted({j for j in array_joints if array_joints.count(j) > 1})
        if twice:
            raise fail(f"joints named twice: {twice}", ("profile", "joints"), expected="each joint once")
        for part, joint in parts.items():
            if joint not in array_joints:
                raise fail(f"joint {joint!r} of part {part!r} is not in the joints list", ("profile", "joints"),
                           expected="a list holding every joint [parts] maps", available=array_joints)
        array_joints = tuple(array_joints)
    return BodyProfile(str(head.get("name", path.stem)), body, tuple(parts.values()), scale, up, path,
                       str(head.get("description", "")), fps, array_joints)
