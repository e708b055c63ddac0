"""The observer's own names for the objects it sees, kept from frame to frame.

Buchsbaum & Blumberg 2005, §4.2 and §6.1: Max sees objects by their colour and remembers where he saw them; what a
world calls its objects is nothing he could see. Each frame the eye reports *detections*: a position, an apparent
radius and a colour (a blob of one colour in the rendered image, or a sphere of the geometric vision). The frame's
detections are matched to the objects seen before (*tracks*) of the same colour, all at once (least total distance,
:func:`scipy.optimize.linear_sum_assignment`), in three rounds: the objects seen in the last frame, within ``gate``
metres (plus the two radii) of where they were, so two cheeses side by side keep their names as they move; then an
object out of sight for at most ``recall`` seconds, wherever one of its colour appeared, the one that vanished last
first (the world moved it in one step, a grasp, or it was moved while hidden); then an object seen longer ago, within the gate of where it was (seen
again where it was). A detection none of them
takes is a new object, named after the kind it looks like (:mod:`plugins.perception.object_looks`): the first
cheese is ``"cheese"``, the next ``"cheese 2"``. An object's size is the median apparent radius of its recent
sightings (a half-hidden object looks smaller, one merged with another of its colour bigger, but not for long), and
its kind is what its colour and that size say.

Tracks are never dropped: an object hidden a while and seen again where it was keeps its name (where it went
meanwhile is what :class:`toolkit.sightings.Sightings` remembers). Their number is bounded by ``limit``: beyond it
the track seen longest ago is forgotten.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from plugins.perception.object_looks import Looks, SeenKind
from toolkit import Parameter

__all__ = ["OBJECT_PARAMETERS", "Detections", "ObjectTracker", "tracker_for"]

OBJECT_PARAMETERS = (
    Parameter("looks", dict, {}, "What each kind of object looks like, which is how seen objects are known (B&B "
              "§4.2): { cheese = { colour = \"#ffd700\", radius = [0.02, 0.10] } } (radius optional: the apparent "
              "radii, metres, that kind comes in). An object no look fits is a thing of its colour (\"thing "
              "#c0c0c0\")."),
    Parameter("tolerance", float, 60.0, "The largest RGB distance (0-441) at which a seen colour is still a known "
              "look's.", minimum=0.0, maximum=442.0),
    Parameter("gate", float, 0.15, "Metres an object may move between two sightings (beyond its radius) and keep "
              "its name.", minimum=0.0),
    Parameter("recall", float, 2.0, "Seconds an object out of sight is still the one of its colour that appears "
              "elsewhere (taken into a hand behind the body, it is seen again in the hand).", minimum=0.0,
              maximum=3600.0),
)
"""The parameters every perception that sees objects shares: looks, colour tolerance, tracking gate."""

RECENT = 15
"""Sightings whose median apparent radius is an object's size."""


def tracker_for(params: dict, fps: float = 30.0) -> "ObjectTracker":
    """A fresh tracker with the looks, tolerance, gate and recall of a perception's ``params``, at ``fps``."""
    return ObjectTracker(Looks(params["looks"], params["tolerance"]), params["gate"],
                         recall=int(round(params["recall"] * fps)))


@dataclass
class Detections:
    """What the eye got of the objects in one frame: positions (n, 3), apparent radii (n,), colours (n, 3) RGB."""

    positions: np.ndarray
    radii: np.ndarray
    colours: np.ndarray

    @classmethod
    def none(cls) -> "Detections":
        return cls(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)))

    def __len__(self) -> int:
        return len(self.radii)


class _Track:
    """One object as the observer knows it: its name, colour, the apparent radii of its recent sightings (the size
    it is taken to have is their median: a half-hidden object looks smaller, one merged with another of its colour
    bigger, but not for long), where it was last seen and when."""

    __slots__ = ("name", "colour", "radii", "kind", "position", "seen")

    def __init__(self, name: str, colour: np.ndarray, position: np.ndarray, seen: int) -> None:
        self.name, self.colour, self.position, self.seen = name, colour, position, seen
        self.radii: deque[float] = deque(maxlen=RECENT)
        self.kind: SeenKind | None = None

    @property
    def radius(self) -> float:
        return float(np.median(self.radii))


class ObjectTracker:
    """Names the detections of each frame, keeping each object's name while it is seen and after (see the module).

    Parameters
    ----------
    looks : Looks
        What the observer knows things look like.
    gate : float
        Metres an object may have moved between two sightings (beyond the two radii) and still be the same.
    recall : int
        Frames an object out of sight is still the one of its colour that appears elsewhere.
    limit : int
        Most objects remembered.
    """

    def __init__(self, looks: Looks, gate: float = 0.15, limit: int = 256, recall: int = 60) -> None:
        self.looks, self.gate, self.limit, self.recall = looks, float(gate), int(limit), int(recall)
        self.tracks: list[_Track] = []
        self._counts: dict[str, int] = {}
        self._frame = 0

    def _name(self, kind: str) -> str:
        n = self._counts.get(kind, 0) + 1
        self._counts[kind] = n
        return kind if n == 1 else f"{kind} {n}"

    def update(self, seen: Detections) -> tuple[dict[str, np.ndarray], dict[str, SeenKind], dict[str, float]]:
        """Name this frame's detections: (name to position, name to kind, name to size as seen)."""
        self._frame += 1
        n = len(seen)
        if n == 0:
            return {}, {}, {}
        owner = self._match(seen)
        positions, named, sizes = {}, {}, {}
        for i in range(n):
            if owner[i] >= 0:
                track = self.tracks[owner[i]]
                track.position, track.seen = seen.positions[i].copy(), self._frame
            else:
                first = self.looks.kind(seen.colours[i], float(seen.radii[i]))
                track = _Track(self._name(first), seen.colours[i].copy(), seen.positions[i].copy(), self._frame)
                self.tracks.append(track)
            before = track.radius if track.radii else None
            track.radii.append(float(seen.radii[i]))
            if track.kind is None or track.radius != before:
                track.kind = self.looks.kind(track.colour, track.radius)
            positions[track.name] = seen.positions[i].copy()
            named[track.name] = track.kind
            sizes[track.name] = track.radius
        if len(self.tracks) > self.limit:
            self.tracks.sort(key=lambda t: -t.seen)
            del self.tracks[self.limit:]
        return positions, named, sizes

    def _match(self, seen: Detections) -> np.ndarray:
        """The track each detection is (-1: none), in three rounds, each the least total distance
        (:func:`scipy.optimize.linear_sum_assignment`) over the pairs it allows: the objects seen last frame, within
        the gate; then those out of sight for at most ``recall`` frames, wherever one of their colour appeared, the
        one that vanished last first (moved in one step, or while hidden: taken into a hand behind the body); then
        those seen longer ago, within the gate (seen again where they were)."""
        owner = np.full(len(seen), -1)
        if not self.tracks:
            return owner
        last = np.array([t.position for t in self.tracks])
        cost = np.linalg.norm(seen.positions[:, None, :] - last[None, :, :], axis=2)
        same = np.abs(seen.colours[:, None, :] - np.array([t.colour for t in self.tracks])[None]).max(axis=2) < 1.0
        near = cost <= self.gate + seen.radii[:, None] + np.array([t.radius for t in self.tracks])[None, :]
        since = self._frame - np.array([t.seen for t in self.tracks])
        recent, lately = since == 1, since <= self.recall
        # out of sight lately: the one that vanished last first, wherever it is now (the nearest among those as long)
        latest = since[None, :] * 1e3 + cost
        for allowed, by in ((same & near & recent, cost), (same & lately, latest), (same & near, cost)):
            allowed = allowed & (owner < 0)[:, None] & ~np.isin(np.arange(len(self.tracks)), owner)[None, :]
            if allowed.any():
                rows, cols = linear_sum_assignment(np.where(allowed, by, 1e9))
                ok = allowed[rows, cols]
                owner[rows[ok]] = cols[ok]
        return owner
