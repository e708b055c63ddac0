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

Several naming schemes of one skeleton share a profile: a part may name a list of joints (aliases), and the first
of them that a file has is the part's joint in that file (``left_hip = ["LeftUpLeg", "LeftHip"]``). Recordings
that need other units, another up axis or other joints have a ``[files."PATTERN"]`` table, matched against each
recording's path (:meth:`BodyProfile.for_file`): a profile per folder or per file, the body (parts, root, facing,
bones) staying the profile's own. A part with no joint of its own (MediaPipe's pelvis) is the mean of several:
``root = {mean = ["left_hip", "right_hip"]}``. ``floor`` (metres, in likeme's frame) is the height of the floor in a
recording whose origin is not on it (a camera's frame: Kinect, MediaPipe); it is subtracted so that the body stands
on ``y = 0``.

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

from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path, PurePath
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

__all__ = ["BodyProfile", "FileRule", "Joint", "MotionStream", "is_profile", "gather_joints", "joint_columns",
           "joint_names", "joint_text", "load_profile", "UNITS", "UP_AXES"]

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

_PROFILE_KEYS = ("name", "description", "units", "up", "fps", "joints", "floor")
_TABLES = ("profile", "parts", "facing", "bones", "colours", "files")
_FILE_KEYS = ("units", "up", "fps", "joints", "floor", "parts")
"""The keys of a ``[files."PATTERN"]`` table: how its recordings are read (the body is the profile's)."""

Joint = str | tuple[str, ...]
"""A part's source in a file: a joint's name, or a tuple of names whose mean is the part (``{mean = [...]}``)."""


def joint_text(joint: Joint) -> str:
    """A part's source as an error message names it: ``'Hips'`` or ``the mean of 'left_hip', 'right_hip'``."""
    return repr(joint) if isinstance(joint, str) else "the mean of " + ", ".join(map(repr, joint))


def joint_names(joints: Iterable[Joint]) -> list[str]:
    """The file's joints that ``joints`` read, each once, in order (the joints of a mean in their order)."""
    out: dict[str, None] = {}
    for j in joints:
        out.update(dict.fromkeys((j,) if isinstance(j, str) else j))
    return list(out)


@dataclass(frozen=True)
class FileRule:
    """How the recordings whose path matches ``pattern`` are read (a ``[files."PATTERN"]`` table of a profile).

    ``pattern`` is matched from the right of the recording's path, as :meth:`pathlib.PurePath.match` does:
    ``"*.csv"``, ``"cmu_*.bvh"``, ``"mixamo/*"`` (every file in a folder ``mixamo``), ``"mixamo/*/*"`` (one folder
    deeper). Every other attribute is None where the table leaves the profile's value; ``parts`` maps some of the
    profile's parts to their joint names in these files (aliases, the first present wins).
    """

    pattern: str
    scale: float | None = None
    up: str | None = None
    fps: float | None = None
    array_joints: tuple[str, ...] | None = None
    floor: float | None = None
    parts: tuple[tuple[str, tuple[Joint, ...]], ...] = ()

    def matches(self, path: str | Path) -> bool:
        return PurePath(path).match(self.pattern)


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
    aliases : tuple of tuple of Joint, or None
        Each part's joint names in order of preference (``joints`` holds the first of each): the first that a file
        has is the part's joint in that file. None: one name per part, ``joints``. A tuple among them is a mean of
        joints (:data:`Joint`).
    floor : float
        The height (metres, likeme's frame) of the floor in the recordings: subtracted from every ``y``.
    files : tuple of FileRule
        The ``[files]`` tables, in the order written: the first whose pattern matches a recording's path says how
        it is read (:meth:`for_file`).
    """

    name: str
    body: Body
    joints: tuple[Joint, ...]
    scale: float = 1.0
    up: str = "+y"
    file: Path | None = None
    description: str = ""
    fps: float | None = None
    array_joints: tuple[str, ...] | None = None
    aliases: tuple[tuple[Joint, ...], ...] | None = None
    files: tuple[FileRule, ...] = ()
    floor: float = 0.0
    rule: FileRule | None = None
    """The ``[files]`` table this profile was made for by :meth:`for_file` (None: the profile's own)."""

    @property
    def names(self) -> tuple[tuple[Joint, ...], ...]:
        """Each part's joint names, in order of preference (the first that a file has wins)."""
        return self.aliases if self.aliases is not None else tuple((j,) for j in self.joints)

    def for_file(self, path: str | Path) -> BodyProfile:
        """This profile as it reads the recording ``path``: the first ``[files."PATTERN"]`` table whose pattern
        matches the path replaces the units, up axis, frame rate, array joints and the joints of the parts it names;
        without a match, the profile itself. The body (parts, root, facing, bones) is always the profile's."""
        rule = next((r for r in self.files if r.matches(path)), None)
        if rule is None:
            return self
        names = dict(zip(self.body.parts, self.names))
        names.update(rule.parts)
        aliases = tuple(names[p] for p in self.body.parts)
        return replace(self, joints=tuple(a[0] for a in aliases), aliases=aliases,
                       scale=self.scale if rule.scale is None else rule.scale, up=rule.up or self.up,
                       fps=self.fps if rule.fps is None else rule.fps,
                       floor=self.floor if rule.floor is None else rule.floor,
                       array_joints=self.array_joints if rule.array_joints is None else rule.array_joints,
                       files=(), rule=rule)

    def resolve(self, names: Sequence[str], source: object = "the recording") -> tuple[Joint, ...]:
        """The joint of each part in a file whose joints are ``names``: the first of the part's names (aliases) the
        file has (a mean, when it has every joint of it). A part none of whose names the file has is a
        :class:`ConfigError` naming the part, the names tried and the file's joints."""
        have = set(names)
        out = []
        for part, options in zip(self.body.parts, self.names):
            found = next((j for j in options if (j in have if isinstance(j, str) else have.issuperset(j))), None)
            if found is None:
                tried = joint_text(options[0]) if len(options) == 1 else \
                    f"(none of {', '.join(map(joint_text, options))})"
                raise ConfigError(f"joint {tried} of part {part!r} is not in {source}", **self._where(part),
                                  expected="a joint of the file", available=list(names))
            out.append(found)
        return tuple(out)

    def for_names(self, names: Sequence[str], source: object = "the recording") -> BodyProfile:
        """This profile with each part's joint the first of its names that ``names`` (a file's joints) holds, and no
        aliases left: for a reader that looks joints up by :attr:`joints` (a live input). Raises as :meth:`resolve`."""
        joints = self.resolve(names, source)
        for part, joint in zip(self.body.parts, joints):
            if not isinstance(joint, str):
                raise ConfigError(f"part {part!r} is {joint_text(joint)}: a live input reads one joint per part",
                                  **self._where(part), expected="a part mapped to one joint of the input")
        return replace(self, joints=joints, aliases=None)

    def _where(self, part: str) -> dict[str, Any]:
        from toolkit.config.toml import find_key_line

        key = ("files", self.rule.pattern, "parts", part) if self.rule is not None and \
            part in dict(self.rule.parts) else ("parts", part)
        return {"file": self.file, "key": key, "line": find_key_line(self.file, key) if self.file else None}

    @property
    def npy_joints(self) -> tuple[str, ...]:
        """The joint names of a ``.npy`` array read through this profile: :attr:`array_joints`, else the mapped
        joints in the order of ``[parts]``, each once."""
        return self.array_joints if self.array_joints is not None else tuple(joint_names(self.joints))

    def check(self, recording: Any) -> list[str]:
        """Raise a :class:`ConfigError` naming any part none of whose joints the recording has (with the joints it
        has); return the joints left unmapped.

        ``recording`` has ``names`` (its joints) and ``source`` (its file name): a
        :class:`~toolkit.recordings.recording.Recording` or a :class:`~toolkit.recordings.bvh.BVH` (a header is enough).
        """
        names = list(recording.names)
        used = set(joint_names(self.resolve(names, recording.source)))
        return [n for n in names if n not in used]

    def convert(self, joint_positions: np.ndarray, names: list[str] | tuple[str, ...]) -> np.ndarray:
        """Source joint positions (F, J, 3) to part positions (F, P, 3) in metres, +y up (each part's joint the
        first of its names that ``names`` holds)."""
        return self._convert(joint_positions, joint_columns(names, self.resolve(names)))

    def _convert(self, joint_positions: np.ndarray, index: list[int | tuple[int, ...]]) -> np.ndarray:
        out = (gather_joints(joint_positions, index) * self.scale) @ UP_AXES[self.up].T
        if self.floor:
            out[..., 1] -= self.floor
        return out

    def motion(self, bvh: BVH) -> Motion:
        """The world positions of the tracked parts over a BVH file's frames (read as :meth:`for_file` says for
        its file)."""
        profile = self.for_file(bvh.source) if bvh.source else self
        joints = profile.resolve(bvh.names, bvh.source)
        return Motion(profile._convert(bvh.positions(), joint_columns(bvh.names, joints)), bvh.fps, self.body.parts)

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
        profile = self.for_file(path)  # a [files] table for this recording, chosen once
        block = BLOCK if block is None else max(1, int(block))
        suffix = recording_format(path)  # an array, and a CSV without a header, have no names of their own
        names = profile.npy_joints if suffix == ".npy" or (suffix == ".csv" and not has_header(path)) else None
        recording = open_recording(path, names=names, fps=fps if fps is not None else profile.fps, frames=block)
        try:
            joints = profile.resolve(recording.names, recording.source)
        except BaseException:
            recording.close()
            raise
        return MotionStream(profile, recording.names, recording.fps, recording.blocks(), recording.close,
                            n_frames=recording.n_frames, joints=joints)


def joint_columns(names: Sequence[str], joints: Sequence[Joint]) -> list[int | tuple[int, ...]]:
    """The column of each of ``joints`` among ``names`` (a tuple of columns for a mean)."""
    where = {n: i for i, n in reversed(list(enumerate(names)))}
    return [where[j] if isinstance(j, str) else tuple(where[k] for k in j) for j in joints]


def gather_joints(values: np.ndarray, index: list[int | tuple[int, ...]]) -> np.ndarray:
    """The columns ``index`` of ``values`` (F, J, 3), a mean of columns where an index is a tuple (NaN where one of
    them is: a mean of joints is seen when all of them are)."""
    if all(isinstance(i, int) for i in index):
        return values[:, index]
    out = values[:, [i if isinstance(i, int) else i[0] for i in index]]
    for p, i in enumerate(index):
        if not isinstance(i, int):
            out[:, p] = values[:, list(i)].mean(axis=1)
    return out


class MotionStream:
    """The blocks of a recording read through a profile (made by :meth:`BodyProfile.stream`).

    ``fps``, ``parts`` and ``joints`` (the file's joint of each part) are known before the first block; iterating
    yields ``(positions, visible)`` blocks, positions (k, P, 3) in metres with +y up and visibility (k, P), as
    :meth:`BodyProfile.read` would give them.
    ``n_frames`` is the file's frame count for a BVH file (from its header), for the other formats the number of
    frames read so far (all of them once iterated). A context manager: leaving it closes the file.
    """

    def __init__(self, profile: BodyProfile, names: Sequence[str], fps: float, blocks: Iterator[np.ndarray],
                 close: Callable[[], Any] | None = None, *, n_frames: int | None = None,
                 joints: Sequence[Joint] | None = None) -> None:
        self.profile, self.names, self._fps = profile, list(names), float(fps)
        self._blocks, self._close, self._n_frames, self._read = blocks, close, n_frames, 0
        self.joints = tuple(joints) if joints is not None else profile.resolve(self.names)
        self._index = joint_columns(self.names, self.joints)

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
            positions = self.profile._convert(values, self._index)
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
    scale = _read_units(head.get("units", "metre"), ("profile", "units"), fail)
    up = _read_up(head.get("up", "+y"), ("profile", "up"), fail)
    parts = table.get("parts")
    if not isinstance(parts, Mapping) or not parts:
        raise fail("missing or empty", ("parts",), expected='a table of part = "source joint" (or a list of '
                                                            'joint names, the first a file has wins)')
    names = {part: _read_names(joint, ("parts", part), fail) for part, joint in parts.items()}
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
    fps = _read_fps(head.get("fps"), ("profile", "fps"), fail)
    array_joints = _read_array_joints(head.get("joints"), names, ("profile", "joints"), fail)
    files = _read_files(table.get("files", {}), names, array_joints, fail)
    aliases = tuple(names.values())
    return BodyProfile(str(head.get("name", path.stem)), body, tuple(a[0] for a in aliases), scale, up, path,
                       str(head.get("description", "")), fps, array_joints,
                       aliases if any(len(a) > 1 for a in aliases) else None, files,
                       _read_floor(head.get("floor", 0.0), ("profile", "floor"), fail))


def _read_floor(floor: Any, key: tuple, fail: Callable[..., ConfigError]) -> float:
    value = finite_number(floor)
    if value is None or isinstance(floor, bool) or abs(value) > 1000:
        raise fail(f"invalid floor {repr(floor)[:40]}", key, expected="the floor's height in metres (likeme's frame, "
                   "after units and up), a finite number, like floor = -1.1")
    return float(value)


def _read_units(units: Any, key: tuple, fail: Callable[..., ConfigError]) -> float:
    """Metres per source unit, from a unit name of :data:`UNITS` or a positive number."""
    if isinstance(units, str):
        if units not in UNITS:
            raise fail(f"unknown units {units!r}", key, expected="a unit name or metres per unit", available=UNITS)
        return UNITS[units]
    if (finite_number(units) or 0.0) > 0:
        return float(units)
    raise fail(f"invalid units {repr(units)[:40]}", key,
               expected="a unit name or a positive number (finite: metres per unit)")


def _read_up(up: Any, key: tuple, fail: Callable[..., ConfigError]) -> str:
    if not isinstance(up, str):
        raise fail(f"wrong type {type(up).__name__} (value {up!r})", key,
                   expected='one axis as a string, like up = "+z"', available=UP_AXES)
    if up not in UP_AXES:
        raise fail(f"unknown up axis {up!r}", key, expected="an axis", available=UP_AXES)
    return up


def _read_names(joint: Any, key: tuple, fail: Callable[..., ConfigError]) -> tuple[Joint, ...]:
    """A part's joint names: one name, a mean ``{mean = [...]}``, or a list of these (aliases) in order of
    preference, each once."""
    expected = ('the name of a source joint, {mean = ["A", "B"]} (the mean of joints), or a list of these (the '
                'first a file has wins), like ["LeftUpLeg", "LeftHip"]')
    options = []
    for option in joint if isinstance(joint, list) else [joint]:
        if isinstance(option, Mapping):
            mean = option.get("mean")
            if set(option) != {"mean"} or not isinstance(mean, list) or len(mean) < 2 or \
                    not all(isinstance(j, str) and j for j in mean) or len(set(mean)) < len(mean):
                raise fail(f"invalid joint {option!r}", key, expected='a mean of two or more joints, each once, like '
                                                                     '{mean = ["left_hip", "right_hip"]}')
            options.append(tuple(mean))
        elif isinstance(option, str) and option:
            options.append(option)
        else:
            raise fail(f"invalid joint {joint!r}", key, expected=expected)
    if not options:
        raise fail(f"invalid joint {joint!r}", key, expected=expected)
    if len(set(options)) < len(options):
        raise fail(f"joint names repeated: {joint}", key, expected="each alias once")
    return tuple(options)


def _read_fps(fps: Any, key: tuple, fail: Callable[..., ConfigError]) -> float | None:
    if fps is None:
        return None
    if isinstance(fps, bool) or not isinstance(fps, int | float) or not MIN_FPS <= fps <= MAX_FPS:  # and NaN
        raise fail(f"invalid fps {fps!r}", key, expected=f"frames per second of recordings without a time of their "
                                                         f"own, a number in {FPS_RANGE}")
    return float(fps)


def _read_array_joints(array_joints: Any, names: Mapping[str, tuple[Joint, ...]], key: tuple,
                       fail: Callable[..., ConfigError]) -> tuple[str, ...] | None:
    """The ``joints`` list (a ``.npy`` array's or a headerless CSV's joints, in order): each once, and for every
    part one of its names."""
    if array_joints is None:
        return None
    if not isinstance(array_joints, list) or not array_joints or \
            not all(isinstance(j, str) and j for j in array_joints):
        raise fail(f"invalid joints {array_joints!r}", key,
                   expected="a list naming the joints of a .npy array in order, like joints = [\"Hips\", ...]")
    twice = sorted({j for j in array_joints if array_joints.count(j) > 1})
    if twice:
        raise fail(f"joints named twice: {twice}", key, expected="each joint once")
    have = set(array_joints)
    for part, options in names.items():
        if not any(j in have if isinstance(j, str) else have.issuperset(j) for j in options):
            joint = options[0] if len(options) == 1 else list(options)
            raise fail(f"joint {joint!r} of part {part!r} is not in the joints list", key,
                       expected="a list holding a joint of every part [parts] maps", available=array_joints)
    return tuple(array_joints)


def _read_files(files: Any, names: Mapping[str, tuple[Joint, ...]], array_joints: tuple[str, ...] | None,
                fail: Callable[..., ConfigError]) -> tuple[FileRule, ...]:
    """The ``[files."PATTERN"]`` tables: for the recordings whose path matches, other units, up axis, frame rate,
    array joints and joints of some parts."""
    if not isinstance(files, Mapping):
        raise fail(f"invalid files {repr(files)[:40]}", ("files",),
                   expected='tables of how some recordings are read, like [files."cmu/*"] units = "inch"')
    rules = []
    for pattern, rule in files.items():
        here = ("files", pattern)
        if not pattern.strip():
            raise fail("an empty pattern", here, expected='a path pattern, like "cmu/*" or "*.csv"')
        if not isinstance(rule, Mapping):
            raise fail(f"invalid {repr(rule)[:40]}", here, expected=f"a table of {', '.join(_FILE_KEYS)}")
        for key in rule:
            if key not in _FILE_KEYS:
                raise fail(f"unknown key {key!r}", (*here, key), expected="a key of a [files] table (the body: "
                           "parts' names, root, facing, bones are the profile's own)", available=_FILE_KEYS)
        parts = rule.get("parts", {})
        if not isinstance(parts, Mapping):
            raise fail(f"invalid parts {repr(parts)[:40]}", (*here, "parts"),
                       expected='a table of part = "source joint" for some of the profile\'s parts')
        for part in parts:
            if part not in names:
                raise fail(f"unknown part {part!r}", (*here, "parts", part), expected="a part of the profile's "
                           "[parts]", available=list(names))
        own = {part: _read_names(joint, (*here, "parts", part), fail) for part, joint in parts.items()}
        merged = {**names, **own}
        joints = rule.get("joints")
        if joints is not None:
            joints = _read_array_joints(joints, merged, (*here, "joints"), fail)
        elif array_joints is not None and own:
            _read_array_joints(list(array_joints), merged, (*here, "parts"), fail)
        rules.append(FileRule(
            pattern, None if "units" not in rule else _read_units(rule["units"], (*here, "units"), fail),
            None if "up" not in rule else _read_up(rule["up"], (*here, "up"), fail),
            _read_fps(rule.get("fps"), (*here, "fps"), fail), joints,
            None if "floor" not in rule else _read_floor(rule["floor"], (*here, "floor"), fail), tuple(own.items())))
    return tuple(rules)
