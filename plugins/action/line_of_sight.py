"""Reading another's line of sight from its head and nose as perceived, with the uncertainty of that perception.

Buchsbaum & Blumberg 2005, §6.1.2: Max "would then try to figure out which object Morris was looking at (using the
location of Morris's head and the tip of his nose, if they are both visible, to determine line of sight)"; and §7.3.1:
"if two objects are extremely close together, Max may pick the wrong one as Morris's object of attention ... a
somewhat 'natural' mistake". Both follow from reading the gaze from what the eye saw:

1. the *gaze* (:func:`perceived_gaze`): the line from the target's head through its nose, in 3D (left-right and
   up-down), from the frames of working memory within :data:`WINDOW` seconds of the moment asked about in which both
   were seen (their mean direction), if any was seen within a second of it;
2. its *uncertainty*: a seen point is off by what the observer's own perception says it may be at that distance
   (:meth:`~plugins.perception.rendered_vision.RenderedVision.position_uncertainty`: a rendered eye's pixels and
   noise; 0 for an exact eye), across the line of sight and along it; the head-to-nose direction is off by the part
   of the two points' errors across that direction over the distance between them (radians,
   :func:`gaze_uncertainty`). The frames averaged make the reading steadier but are not counted as more certain:
   much of a camera's error (the pixel grid) repeats from frame to frame while the head is still;
3. the objects *in sight* (:func:`in_sight`): each object's angle from the gaze (3D) less its angular radius as seen
   from the head; every object within :data:`SIGMAS` uncertainties of the gaze is a candidate, together; if none is,
   the object nearest the gaze within ``sight_angle`` degrees is the one (the paper's plain reading, exact when the
   eye is). Objects close together fall within the uncertainty together, and the observer's habits or its own
   preference (the closest) then choose among them (:mod:`plugins.action.behaviour_identification`); objects far
   apart do not; a cheese above a ball in the same direction is told apart by the gaze's height.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["SIGMAS", "WINDOW", "Gaze", "gaze_uncertainty", "in_sight", "perceived_gaze"]

SIGMAS = 2.0
"""How many standard deviations of the gaze's uncertainty an object may lie off the gaze and still be in sight."""

WINDOW = 0.2
"""Seconds on each side of the moment asked about over which the gaze is read (its mean direction)."""


@dataclass(frozen=True)
class Gaze:
    """The target's line of sight as perceived: from ``head`` along the unit ``direction`` (3,), give or take
    ``sigma`` radians; read from ``frames`` frames around working memory row ``row``."""

    head: np.ndarray
    direction: np.ndarray
    sigma: float
    frames: int
    row: int

    def angles(self, points: np.ndarray) -> np.ndarray:
        """The angle (radians, 3D) between the gaze and the line from the head to each of ``points`` (n, 3)."""
        to = np.asarray(points, dtype=float).reshape(-1, 3) - self.head
        length = np.linalg.norm(to, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            cos = (to @ self.direction) / length
        return np.where(length > 1e-9, np.arccos(np.clip(cos, -1.0, 1.0)), np.inf)


def gaze_uncertainty(head: np.ndarray, nose: np.ndarray, eye: np.ndarray | None, perception: Any) -> float:
    """The standard deviation (radians) of the head-to-nose direction as ``perception`` sees it from ``eye``.

    Each point is off by ``across`` (m) in the two directions across the eye's line of sight and ``along`` (m) along
    it (:meth:`position_uncertainty` of the perception; none: exact). Across the gaze direction ``g`` the spread per
    axis is ``across^2 + (along^2 - across^2) * (1 - (g . e)^2) / 2``, ``e`` the eye's line of sight; the direction
    is off by the two points' spreads over their distance."""
    known = getattr(perception, "position_uncertainty", None)
    gaze = np.asarray(nose, dtype=float) - np.asarray(head, dtype=float)
    length = float(np.linalg.norm(gaze))
    if known is None or eye is None or length < 1e-9:
        return 0.0
    g = gaze / length
    total = 0.0
    for point in (head, nose):
        ray = np.asarray(point, dtype=float) - np.asarray(eye, dtype=float)
        distance = float(np.linalg.norm(ray))
        across, along = (float(np.asarray(x)) for x in known(distance))
        slant = 1.0 - float(g @ ray / distance) ** 2 if distance > 1e-9 else 1.0
        total += across**2 + (along**2 - across**2) * slant / 2
    return float(np.sqrt(total) / length)


def perceived_gaze(observer: Any, row: int, parts: tuple[str, str]) -> Gaze | None:
    """The target's gaze around working memory row ``row`` as the observer perceived it (see the module); ``None``
    when its head and nose (``parts``) were not both seen within a second of it."""
    memory = observer.memory
    if memory is None or memory.n == 0:
        return None
    names = memory.parts  # the observer's own parts, onto which it perceives the target's
    if parts[0] not in names or parts[1] not in names:
        return None
    a, b = names.index(parts[0]), names.index(parts[1])
    both = memory.visible[:, a] & memory.visible[:, b]
    if not both.any():
        return None
    rows = np.flatnonzero(both) + memory.offset  # row numbers since watching began
    nearest = int(rows[np.argmin(np.abs(rows - row))])
    if abs(nearest - row) > memory.fps:  # nothing seen within a second of the movement
        return None
    near = rows[np.abs(rows - nearest) <= WINDOW * memory.fps] - memory.offset
    head, nose = memory.world[near, a], memory.world[near, b]
    lines = nose - head
    lengths = np.linalg.norm(lines, axis=1)
    ok = lengths > 1e-9
    if not ok.any():
        return None
    direction = (lines[ok] / lengths[ok, None]).mean(axis=0)
    if np.linalg.norm(direction) < 1e-9:
        return None
    direction = direction / np.linalg.norm(direction)
    mid = len(near) // 2
    perception = getattr(getattr(observer, "character", None), "perception", None)
    eye = _eye(observer, perception)
    sigma = gaze_uncertainty(head[mid], nose[mid], eye, perception)
    return Gaze(head[ok].mean(axis=0), direction, sigma, int(ok.sum()), nearest)


def _eye(observer: Any, perception: Any) -> np.ndarray | None:
    """Where the observer's eye is (its perception's ``eye`` part), if it can say."""
    eye = getattr(perception, "eye", None)
    if eye is None:
        return None
    try:
        return np.asarray(eye(observer), dtype=float)
    except (AttributeError, TypeError, ValueError, KeyError):
        return None


def in_sight(gaze: Gaze, objects: dict[str, Any], sight_angle: float, *, holder: str | None = None
             ) -> list[tuple[str, float]]:
    """The objects the gaze may be on, nearest the gaze first, with each one's angle off it (degrees, its angular
    radius taken off): every object within :data:`SIGMAS` uncertainties, else the nearest within ``sight_angle``
    degrees (see the module). Objects held by someone other than ``holder`` are left out."""
    names = [n for n, o in objects.items() if o.held_by is None or o.held_by == holder]
    if not names:
        return []
    centres = np.array([objects[n].position for n in names], dtype=float)
    angles = gaze.angles(centres)
    distance = np.linalg.norm(centres - gaze.head, axis=1)
    radii = np.array([float(objects[n].radius) for n in names])
    with np.errstate(invalid="ignore", divide="ignore"):
        size = np.arcsin(np.clip(radii / np.maximum(distance, 1e-9), 0.0, 1.0))
    off = np.maximum(angles - size, 0.0)
    limit = np.radians(sight_angle)
    order = np.argsort(off, kind="stable")
    within = [i for i in order if off[i] <= SIGMAS * gaze.sigma and angles[i] <= limit]
    if not within:
        within = [i for i in order[:1] if angles[i] <= limit]
    return [(names[i], float(np.degrees(off[i]))) for i in within]
