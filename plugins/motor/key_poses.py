"""Timed key poses: the authoring format of movements, and their interpolation into motions.

Buchsbaum & Blumberg 2005, §4.1: source animation is broken into *poses*
corresponding to key-frames, and *movements* are connected poses played by
interpolating between them. This module reads that declaration from a motor
table and samples it; motor systems (``keyframe``, ``posegraph``) build on it.

Declaration (inside a character's ``[motor]`` table)::

    [motor.poses.stand]              # every part, local frame, metres
    root = [0.0, 0.30, 0.0]
    ...
    [motor.poses.crouch]
    base = "stand"                   # start from another pose
    shift = [0.0, -0.06, 0.0]        # move every part (optional)
    offset = { left_knee = [0.0, -0.03, 0.06] }   # move some parts (optional)
    nose = [0.0, 0.50, 0.12]         # or place a part absolutely

    [motor.movements.jump]
    keys = [{ pose = "stand", at = 0.0 }, { pose = "crouch", at = 0.25 }, ...]   # at: seconds

A body with hands (:class:`toolkit.body.Hand`) gives each finger as three joint
angles in *degrees* (``left_index = [70, 80, 0]``: base flexion, middle
flexion, spread); they are held in radians. ``shift`` moves positions only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from toolkit.body import Body
from toolkit.errors import ConfigError
from toolkit.motion import Motion
from toolkit.params import Parameter

__all__ = ["KeyPoses", "Movement", "REPERTOIRE_PARAMETERS", "parse_poses", "parse_movements", "read_repertoire", "interpolate", "sample"]

POSE_KEYS = ("base", "shift", "offset")

REPERTOIRE_PARAMETERS = (
    Parameter("rest", str, "stand", "The hub pose the character stands in when idle."),
    Parameter("hubs", list, [], "Further hub poses movements may start and end in (the rest pose always is one).", items=str),
    Parameter("poses", dict, doc="Named key poses, local frame, metres (see the character format)."),
    Parameter("movements", dict, doc="Named movements: key poses at times in seconds."),
)
"""The parameters of every motor system whose repertoire is declared as timed key poses."""


@dataclass(frozen=True)
class Movement:
    """A movement: named key poses at times (seconds from its start)."""

    name: str
    poses: tuple[str, ...]
    times: np.ndarray
    description: str = ""

    @property
    def duration(self) -> float:
        return float(self.times[-1])


@dataclass(frozen=True)
class KeyPoses:
    """Named poses as one contiguous array: ``array[i]`` is pose ``names[i]``, shape (N, P, 3)."""

    names: tuple[str, ...]
    array: np.ndarray

    def __getitem__(self, name: str) -> np.ndarray:
        return self.array[self.index[name]]

    @cached_property
    def index(self) -> dict[str, int]:
        """Pose name -> its row of ``array`` (a character of thousands of poses looks each up in constant time)."""
        return {name: i for i, name in enumerate(self.names)}


def _vec(value: Any, key: tuple, *, angles: bool = False) -> np.ndarray:
    if (
        not isinstance(value, list)
        or len(value) != 3
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        or not np.all(np.isfinite(value))
    ):
        expected = "[base, middle, spread] finger joint angles in degrees" if angles else "[x, y, z] finite numbers in metres"
        raise ConfigError(f"invalid value {value!r}", key=key, expected=expected)
    return np.radians(np.asarray(value, dtype=float)) if angles else np.asarray(value, dtype=float)


def parse_poses(table: Mapping[str, Any], body: Body) -> KeyPoses:
    """Resolve a ``poses`` table (with ``base`` references) into full poses of ``body``.

    Errors carry key paths relative to the motor table (``("poses", name, part)``).
    """
    if not table:
        raise ConfigError("no poses declared", key=("poses",), expected="at least one [motor.poses.NAME] table")
    resolved: dict[str, np.ndarray] = {}

    def resolve(name: str, chain: tuple[str, ...]) -> np.ndarray:
        if name in resolved:
            return resolved[name]
        spec = table[name]
        key = ("poses", name)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="a table of part positions")
        for k in spec:
            if k not in POSE_KEYS and k not in body.parts:
                raise ConfigError(
                    f"unknown key {k!r}", key=(*key, k), expected="a body part or base/shift/offset", available=(*body.parts, *POSE_KEYS)
                )
        base = spec.get("base")
        if base is not None:
            if not isinstance(base, str) or base not in table:
                raise ConfigError(f"unknown pose {base!r}", key=(*key, "base"), expected="the name of a declared pose", available=sorted(table))
            if base in chain:
                raise ConfigError(f"pose base cycle: {' -> '.join((*chain, name, base))}", key=(*key, "base"), expected="no cycle")
            pose = resolve(base, (*chain, name)).copy()
        else:
            missing = [p for p in body.parts if p not in spec]
            if missing:
                raise ConfigError(
                    f"pose without base misses parts {missing}", key=key, expected="a position for every part, or base = POSE"
                )
            pose = np.zeros((body.n_parts, 3))
        angles = body.angle_mask
        if "shift" in spec:
            pose[~angles] += _vec(spec["shift"], (*key, "shift"))
        offsets = spec.get("offset", {})
        if not isinstance(offsets, Mapping):
            raise ConfigError("not a table", key=(*key, "offset"), expected="a table of part = [dx, dy, dz]")
        for part, value in offsets.items():
            i = body.index(part, key=(*key, "offset", part))
            pose[i] += _vec(value, (*key, "offset", part), angles=angles[i])
        for i, part in enumerate(body.parts):
            if part in spec:
                pose[i] = _vec(spec[part], (*key, part), angles=angles[i])
        resolved[name] = pose
        return pose

    names = tuple(table)
    array = np.stack([resolve(n, ()) for n in names])
    return KeyPoses(names, array)


def parse_movements(table: Mapping[str, Any], poses: KeyPoses, hubs: Sequence[str]) -> dict[str, Movement]:
    """Read a ``movements`` table; every movement must start and end in a hub pose (§5.1)."""
    if not table:
        raise ConfigError("no movements declared", key=("movements",), expected="at least one [motor.movements.NAME] table")
    out: dict[str, Movement] = {}
    for name, spec in table.items():
        key = ("movements", name)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="a table with keys = [...]")
        for k in spec:
            if k not in ("keys", "description"):
                raise ConfigError(f"unknown key {k!r}", key=(*key, k), expected="a movement key", available=("description", "keys"))
        keys = spec.get("keys")
        if not isinstance(keys, list) or len(keys) < 2:
            raise ConfigError("missing or too short", key=(*key, "keys"), expected='two or more { pose = "...", at = seconds }')
        names, times = [], []
        for i, k in enumerate(keys):
            kk = (*key, "keys", i)
            if not isinstance(k, Mapping) or set(k) != {"pose", "at"}:
                raise ConfigError(f"invalid key pose {k!r}", key=kk, expected='{ pose = "NAME", at = SECONDS }')
            if k["pose"] not in poses.names:
                raise ConfigError(f"unknown pose {k['pose']!r}", key=(*kk, "pose"), expected="a declared pose", available=poses.names)
            at = k["at"]
            if isinstance(at, bool) or not isinstance(at, (int, float)) or not np.isfinite(at):
                raise ConfigError(f"invalid time {at!r}", key=(*kk, "at"), expected="seconds as a number")
            names.append(k["pose"])
            times.append(float(at))
        t = np.asarray(times)
        if t[0] != 0.0 or np.any(np.diff(t) <= 0):
            raise ConfigError(f"key times {times} are not increasing from 0", key=(*key, "keys"), expected="times starting at 0 and strictly increasing")
        for end, idx in (("start", 0), ("end", -1)):
            if names[idx] not in hubs:
                raise ConfigError(
                    f"movement must {end} in a hub pose, not {names[idx]!r}", key=(*key, "keys"), expected="a hub pose", available=tuple(hubs)
                )
        description = spec.get("description", "")
        out[name] = Movement(name, tuple(names), t, str(description))
    return out


def read_repertoire(params: Mapping[str, Any], body: Body) -> tuple[KeyPoses, tuple[str, ...], dict[str, Movement]]:
    """Poses, hubs and movements from a motor table's ``poses``, ``rest``, ``hubs`` and ``movements``."""
    key_poses = parse_poses(params["poses"], body)
    hubs = (params["rest"], *params["hubs"])
    for i, hub in enumerate(hubs):
        if hub not in key_poses.names:
            raise ConfigError(
                f"unknown hub pose {hub!r}",
                key=("rest",) if i == 0 else ("hubs", i - 1),
                expected="a declared pose",
                available=key_poses.names,
            )
    return key_poses, hubs, parse_movements(params["movements"], key_poses, hubs)


def play(key_poses: KeyPoses, movement: Movement, parts: Sequence[str], *, fps: float, speed: float = 1.0) -> Motion:
    """Sample one authored movement into a motion."""
    keys = np.stack([key_poses[p] for p in movement.poses])
    return interpolate(keys, movement.times, parts, fps=fps, speed=speed)


def interpolate(
    key_poses: np.ndarray, times: np.ndarray, parts: Sequence[str], *, fps: float, speed: float = 1.0
) -> Motion:
    """Sample key poses (K, P, 3) at ``times`` (K,) into a motion at ``fps`` (see :func:`sample`)."""
    values = sample(key_poses, times, fps=fps, speed=speed)
    return Motion(values, fps, parts)


def sample(key_poses: np.ndarray, times: np.ndarray, *, fps: float, speed: float = 1.0) -> np.ndarray:
    """Key poses (K, ...) at ``times`` (K,) sampled at ``fps``: an array (n, ...), n = round(duration * fps) + 1.

    Shape-preserving cubic (PCHIP) interpolation: no overshoot past a key, zero
    velocity where the motion turns. ``speed`` > 1 plays faster. The first and
    last frames are exactly the first and last keys. Every coordinate is
    interpolated on its own, so the key poses of several movements with the same
    key times, stacked on a second axis (K, M, P, 3), are sampled in one call
    with the numbers each would get alone.
    """
    from scipy.interpolate import PchipInterpolator

    if speed <= 0:
        raise ValueError("speed must be positive")
    key_poses = np.asarray(key_poses)
    duration = float(times[-1]) / speed
    n = max(2, int(round(duration * fps)) + 1)
    t = np.linspace(0.0, float(times[-1]), n)
    flat = key_poses.reshape(len(times), -1)
    if len(times) == 2:
        values = flat[0] + (t / times[-1])[:, None] * (flat[1] - flat[0])
    else:
        values = PchipInterpolator(times, flat, axis=0)(t)
    return values.reshape(n, *key_poses.shape[1:])
