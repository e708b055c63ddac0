"""Motions and poses as numpy arrays, and the frame conventions between world and body.

A :class:`Motion` is the one container that flows through the pipeline:
``positions`` of shape ``(F, P, 3)``, a ``visible`` mask of shape ``(F, P)``,
a frame rate and the part names. A :class:`Pose` is one frame of it.
Coordinates that are not finite (NaN, inf) are never visible: the mask is
cleared for them when the object is built, so a bad frame is "not seen" rather
than an error.

Frames (see :mod:`toolkit.body` for the axes):

- :func:`local_to_world` places local-frame points at a ground position and
  heading; :func:`world_to_local` undoes it. Headings are radians about ``+y``;
  heading 0 faces ``+z`` and the facing direction is ``(sin h, 0, cos h)``.
- :meth:`Motion.root_relative` subtracts the root part from every part.

Hidden parts (``docs/conventions.md``): ``visible`` says what was seen; what a hidden part's coordinates hold is
fixed by one rule, :func:`fill_hidden`: the value it had when it was last seen (sample and hold), before its first
sighting the value of that sighting, and NaN for a part never seen at all (or ``default``, where a caller has an
assumption to put there). Working memory (:class:`toolkit.watching.ObservationLog`) keeps every observation that
way, so segmenters and matchers never fill hidden parts themselves. :meth:`Motion.onto` maps a motion onto
another body's parts by name.

Operations return new objects; nothing here modifies its input.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Motion",
    "Pose",
    "concatenate",
    "fill_hidden",
    "part_index",
    "heading_matrix",
    "local_to_world",
    "world_to_local",
    "facing_vector",
]


def _as_mask(visible: np.ndarray | None, positions: np.ndarray) -> np.ndarray:
    finite = np.isfinite(positions).all(axis=-1)
    if visible is None:
        return finite
    mask = np.asarray(visible, dtype=bool)
    if mask.shape != finite.shape:
        raise ValueError(f"visible has shape {mask.shape}, expected {finite.shape}")
    return mask & finite


@dataclass(frozen=True, eq=False)
class Pose:
    """Positions of the parts at one instant.

    Attributes
    ----------
    positions : array, shape (P, 3)
    visible : array of bool, shape (P,)
    parts : tuple of str, length P
    """

    positions: np.ndarray
    visible: np.ndarray
    parts: tuple[str, ...]

    def __post_init__(self) -> None:
        positions = np.asarray(self.positions, dtype=float)
        if positions.shape != (len(self.parts), 3):
            raise ValueError(f"pose positions have shape {positions.shape}, expected ({len(self.parts)}, 3)")
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "visible", _as_mask(self.visible, positions))
        object.__setattr__(self, "parts", tuple(self.parts))

    def __getitem__(self, part: str) -> np.ndarray:
        return self.positions[self.parts.index(part)]


@dataclass(frozen=True, eq=False)
class Motion:
    """A sequence of poses sampled at a fixed frame rate.

    Attributes
    ----------
    positions : array, shape (F, P, 3)
        Part positions, in whatever frame the producer states (local, world or root-relative).
    visible : array of bool, shape (F, P)
        Whether each part was seen in each frame; always false where a coordinate is not finite.
    fps : float
        Frames per second.
    parts : tuple of str, length P
    world : array, shape (F, P, 3), or None
        Where ``positions`` are root-relative (§5.1 of Buchsbaum & Blumberg 2005), the same parts' world positions
        in the same frames, when the producer knows them (NaN where not): what the root-relative transform removes
        (where the body travels, and its facing) stays available. ``None`` when not known.
    """

    positions: np.ndarray
    visible: np.ndarray
    fps: float
    parts: tuple[str, ...]
    world: np.ndarray | None

    def __init__(
        self,
        positions: np.ndarray,
        fps: float,
        parts: Sequence[str],
        visible: np.ndarray | None = None,
        world: np.ndarray | None = None,
    ) -> None:
        positions = np.asarray(positions, dtype=float)
        parts = tuple(parts)
        if positions.ndim != 3 or positions.shape[1:] != (len(parts), 3):
            raise ValueError(f"motion positions have shape {positions.shape}, expected (frames, {len(parts)}, 3)")
        if not (np.isfinite(fps) and fps > 0):
            raise ValueError(f"fps must be a positive number, got {fps!r}")
        if world is not None:
            world = np.asarray(world, dtype=float)
            if world.shape != positions.shape:
                raise ValueError(f"motion world positions have shape {world.shape}, expected {positions.shape}")
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "visible", _as_mask(visible, positions))
        object.__setattr__(self, "fps", float(fps))
        object.__setattr__(self, "parts", parts)
        object.__setattr__(self, "world", world)

    # -- shape -------------------------------------------------------------------

    @property
    def n_frames(self) -> int:
        return self.positions.shape[0]

    @property
    def n_parts(self) -> int:
        return self.positions.shape[1]

    @property
    def duration(self) -> float:
        """Seconds from the first to one frame past the last frame."""
        return self.n_frames / self.fps

    @property
    def times(self) -> np.ndarray:
        """Time of each frame in seconds from the first, shape (F,)."""
        return np.arange(self.n_frames) / self.fps

    def __len__(self) -> int:
        return self.n_frames

    def pose(self, frame: int) -> Pose:
        return Pose(self.positions[frame], self.visible[frame], self.parts)

    # -- pure operations ---------------------------------------------------------

    def slice(self, start: int, stop: int | None = None) -> Motion:
        """Frames ``start`` to ``stop`` (exclusive), as a new motion."""
        return Motion(self.positions[start:stop], self.fps, self.parts, self.visible[start:stop],
                      None if self.world is None else self.world[start:stop])

    def select(self, parts: Sequence[str]) -> Motion:
        """Only the named parts, in the given order."""
        idx = [self.parts.index(p) for p in parts]
        return Motion(self.positions[:, idx], self.fps, parts, self.visible[:, idx],
                      None if self.world is None else self.world[:, idx])

    def root_relative(self, root: str) -> Motion:
        """Every part minus the root part, frame by frame (translation only).

        Frames where the root is not visible become entirely invisible: without
        the root there is no reference point (§5.1). The positions before the
        subtraction become :attr:`world` (unless the motion already has one).
        """
        r = self.parts.index(root)
        rel = self.positions - self.positions[:, r : r + 1, :]
        visible = self.visible & self.visible[:, r : r + 1]
        return Motion(rel, self.fps, self.parts, visible, self.positions if self.world is None else self.world)

    def onto(self, parts: Sequence[str]) -> Motion:
        """The same motion in the order of ``parts``, taken by name; a part this motion lacks is never visible
        (its coordinates NaN)."""
        parts = tuple(parts)
        if parts == self.parts:
            return self
        index = part_index(self.parts, parts)
        have = index >= 0
        positions = np.full((self.n_frames, len(parts), 3), np.nan)
        visible = np.zeros((self.n_frames, len(parts)), dtype=bool)
        positions[:, have] = self.positions[:, index[have]]
        visible[:, have] = self.visible[:, index[have]]
        world = None
        if self.world is not None:
            world = np.full((self.n_frames, len(parts), 3), np.nan)
            world[:, have] = self.world[:, index[have]]
        return Motion(positions, self.fps, parts, visible, world)

    def filled(self, default: np.ndarray | None = None) -> Motion:
        """The same motion with hidden parts' coordinates set by :func:`fill_hidden` (the mask unchanged)."""
        return Motion(fill_hidden(self.positions, self.visible, default), self.fps, self.parts, self.visible,
                      self.world)

    def visible_fraction(self) -> float:
        """Share of (frame, part) cells that are visible; 0.0 for an empty motion."""
        return float(self.visible.mean()) if self.visible.size else 0.0

    def __repr__(self) -> str:
        return f"Motion({self.n_frames} frames x {self.n_parts} parts @ {self.fps:g} fps)"


def concatenate(motions: Sequence[Motion]) -> Motion:
    """Join motions of the same parts and frame rate end to end."""
    if not motions:
        raise ValueError("concatenate needs at least one motion")
    first = motions[0]
    for m in motions[1:]:
        if m.parts != first.parts or m.fps != first.fps:
            raise ValueError("motions to concatenate must share parts and fps")
    return Motion(
        np.concatenate([m.positions for m in motions]),
        first.fps,
        first.parts,
        np.concatenate([m.visible for m in motions]),
        np.concatenate([m.world for m in motions]) if all(m.world is not None for m in motions) else None,
    )


def part_index(source: Sequence[str], parts: Sequence[str]) -> np.ndarray:
    """For each name of ``parts``, its index in ``source`` (-1 where ``source`` has no part of that name)."""
    where = {name: i for i, name in enumerate(source)}
    return np.array([where.get(name, -1) for name in parts], dtype=np.intp)


def fill_hidden(positions: np.ndarray, visible: np.ndarray, default: np.ndarray | None = None) -> np.ndarray:
    """Coordinates of hidden parts by the one rule of likeme (``docs/conventions.md``).

    A hidden part holds the value it had when it was last seen; before its first sighting it holds the value of
    that sighting; a part never seen is NaN, or its row of ``default`` when one is given.

    Parameters
    ----------
    positions : array, shape (F, P, 3)
    visible : array of bool, shape (F, P)
    default : array, shape (P, 3), optional
        What a never-seen part is assumed to be (a motor system puts its own rest posture there).

    Returns
    -------
    array, shape (F, P, 3)
        A new array; visible coordinates unchanged.
    """
    positions = np.asarray(positions, dtype=float)
    visible = np.asarray(visible, dtype=bool)
    n, p = visible.shape
    if n == 0:
        return positions.copy()
    last = np.where(visible, np.arange(n)[:, None], -1)
    np.maximum.accumulate(last, axis=0, out=last)  # the last frame each part was seen, up to each frame
    ever = visible.any(axis=0)
    first = np.argmax(visible, axis=0)  # the first sighting (0 for a part never seen)
    rows = np.where(last >= 0, last, first[None, :])
    out = positions[rows, np.arange(p)[None, :]]
    out[:, ~ever] = np.nan if default is None else np.asarray(default, dtype=float)[~ever]
    return out


# -- frames ---------------------------------------------------------------------


def heading_matrix(heading: float | np.ndarray) -> np.ndarray:
    """Rotation about ``+y`` by ``heading`` radians; shape (3, 3) or (..., 3, 3)."""
    h = np.asarray(heading, dtype=float)
    c, s = np.cos(h), np.sin(h)
    zero, one = np.zeros_like(h), np.ones_like(h)
    return np.stack(
        [np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1), np.stack([-s, zero, c], -1)],
        axis=-2,
    )


def facing_vector(heading: float | np.ndarray) -> np.ndarray:
    """Unit facing direction(s) on the ground for heading(s), shape (..., 3)."""
    h = np.asarray(heading, dtype=float)
    return np.stack([np.sin(h), np.zeros_like(h), np.cos(h)], axis=-1)


def local_to_world(points: np.ndarray, position: np.ndarray, heading: float | np.ndarray) -> np.ndarray:
    """Place local-frame points (..., 3) at a world ``position`` (3,) facing ``heading``.

    ``heading`` and ``position`` may carry a leading frame axis matching ``points``
    of shape (F, P, 3): heading (F,), position (F, 3).
    """
    points = np.asarray(points, dtype=float)
    rot = heading_matrix(heading)
    position = np.asarray(position, dtype=float)
    if rot.ndim == 3:  # per frame
        out = np.einsum("fij,fpj->fpi", rot, points)
        return out + position.reshape(-1, 1, 3)
    return points @ rot.T + position


def world_to_local(points: np.ndarray, position: np.ndarray, heading: float | np.ndarray) -> np.ndarray:
    """Inverse of :func:`local_to_world`."""
    points = np.asarray(points, dtype=float)
    rot = heading_matrix(heading)
    position = np.asarray(position, dtype=float)
    if rot.ndim == 3:
        return np.einsum("fji,fpj->fpi", rot, points - position.reshape(-1, 1, 3))
    return (points - position) @ rot
