"""Body profiles: how a motion-capture skeleton becomes a likeme body.

A profile is a TOML file (``docs/conventions.md`` has the format) saying which
source joints are the tracked body parts, which part is the root, which parts
give the facing (a left/right pair and an optional forward marker, like the
paper's knees and nose), the source's up axis and its units. Reading a BVH file
through a profile gives a :class:`~toolkit.motion.Motion` of world positions in
metres with ``+y`` up, one column per tracked part, and the :class:`Body` to
perceive it with.

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

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.body import Body
import toolkit.bvh as bvh_module
from toolkit.bvh import BVH, BVHStream, open_bvh, read_bvh
from toolkit.errors import ConfigError
from toolkit.files import check_regular_file
from toolkit.motion import Motion
from toolkit.params import finite_number

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

_PROFILE_KEYS = ("name", "description", "units", "up")
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
    """

    name: str
    body: Body
    joints: tuple[str, ...]
    scale: float = 1.0
    up: str = "+y"
    file: Path | None = None
    description: str = ""

    def _where(self, part: str) -> dict[str, Any]:
        from toolkit.character import find_key_line

        key = ("parts", part)
        return {"file": self.file, "key": key, "line": find_key_line(self.file, key) if self.file else None}

    def check(self, bvh: BVH) -> list[str]:
        """Raise a :class:`ConfigError` naming any mapped joint the file lacks; return the joints left unmapped."""
        names = bvh.names
        for part, joint in zip(self.body.parts, self.joints):
            if joint not in names:
                raise ConfigError(f"joint {joint!r} of part {part!r} is not in {bvh.source}", **self._where(part),
                                  expected="a joint of the file", available=names)
        used = set(self.joints)
        return [n for n in names if n not in used]

    def convert(self, joint_positions: np.ndarray, names: list[str]) -> np.ndarray:
        """Source joint positions (F, J, 3) to part positions (F, P, 3) in metres, +y up."""
        index = [names.index(j) for j in self.joints]
        return (joint_positions[:, index] * self.scale) @ UP_AXES[self.up].T

    def motion(self, bvh: BVH) -> Motion:
        """The world positions of the tracked parts over the file's frames."""
        self.check(bvh)
        return Motion(self.convert(bvh.positions(), bvh.names), bvh.fps, self.body.parts)

    def read(self, path: str | Path) -> Motion:
        """Read a BVH file and return its motion through this profile."""
        return self.motion(read_bvh(path))

    def stream(self, path: str | Path, block: int | None = None) -> MotionStream:
        """A BVH file's motion through this profile, ``block`` frames at a time (:class:`MotionStream`).

        ``block`` defaults to :data:`toolkit.bvh.BLOCK`. The header is read and checked against the profile at
        once; the frames follow as they are iterated, with forward kinematics run per block, so the memory does not
        grow with the file. The blocks are ``profile.read(path)`` sliced, bit for bit, and a bad value raises the
        error ``read`` raises.
        """
        bvh = open_bvh(path)
        try:
            self.check(bvh.header)
        except BaseException:
            bvh.close()
            raise
        return MotionStream(self, bvh, bvh_module.BLOCK if block is None else block)


class MotionStream:
    """The blocks of a motion file read through a profile (made by :meth:`BodyProfile.stream`).

    ``fps``, ``n_frames`` and ``parts`` are known before the first block; iterating yields ``(positions, visible)``
    blocks, positions (k, P, 3) in metres with +y up and visibility (k, P), as :meth:`BodyProfile.read` would give
    them. A context manager: leaving it closes the file.
    """

    def __init__(self, profile: BodyProfile, bvh: BVHStream, block: int) -> None:
        self.profile, self.bvh, self.block = profile, bvh, max(1, int(block))

    @property
    def fps(self) -> float:
        return self.bvh.fps

    @property
    def n_frames(self) -> int:
        return self.bvh.n_frames

    @property
    def parts(self) -> list[str]:
        return list(self.profile.body.parts)

    def __iter__(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        header, names = self.bvh.header, self.bvh.names
        for values in self.bvh.blocks(self.block):
            positions = self.profile.convert(header._kinematics(values)[0], names)
            yield positions, np.isfinite(positions).all(axis=-1)

    def close(self) -> None:
        self.bvh.close()

    def __enter__(self) -> MotionStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def is_profile(table: Mapping[str, Any]) -> bool:
    """Whether a parsed TOML table is a body profile (it has a ``[profile]`` or ``[parts]`` table, no ``[character]``)."""
    return "character" not in table and ("profile" in table or "parts" in table)


def load_profile(path: str | Path) -> BodyProfile:
    """Read a body profile TOML file; every problem is a :class:`ConfigError` naming the file, key and line."""
    from toolkit.character import check_body, find_key_line, read_toml

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
    return BodyProfile(str(head.get("name", path.stem)), body, tuple(parts.values()), scale, up, path,
                       str(head.get("description", "")))
