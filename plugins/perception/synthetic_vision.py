"""Perception ``synthetic-vision``: what the observer's eye can see of the target, found by geometry (the fast setting).

Buchsbaum & Blumberg 2005, §4.2 and §5.1. The observer sees the target's
colour-coded body parts from its own eye: only parts inside its field of view
and range, and not hidden behind another part or an object (when Morris covers
his face, his hands hide his nose, §5.2.3); objects it sees likewise, unless hidden
behind the target's body or another object (a box in front of the cheese). From the visible parts it finds the
target's root and facing (the nose against the knees, :mod:`plugins.lib.root_frame`)
and converts what it sees to root-relative coordinates.

This plugin computes visibility geometrically: every part and object is a
sphere, and a part is occluded when the line of sight from the eye to it passes
through a nearer sphere. ``rendered-vision`` renders the colour-coded image and reads it back, as the paper does
(the B&B characters' default); this one is its fast geometric stand-in. Objects are seen as what they look like
(their colour and size, :mod:`plugins.perception.object_looks`) and named by the observer
(:mod:`plugins.perception.object_tracking`), never by what the world calls them. Optional Gaussian noise and random
dropouts make the input as bad as real vision; a sensory buffer
(:mod:`plugins.perception.sensory_buffer`) bridges dropouts shorter than ``buffer`` seconds.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plugins.lib.root_frame import HeadingFilter, root_relative
from plugins.perception.object_looks import rgb_of
from plugins.perception.object_tracking import OBJECT_PARAMETERS, Detections, ObjectTracker, tracker_for
from plugins.perception.sensory_buffer import SensoryBuffer
from toolkit import ConfigError, Parameter, Percept, Perception, hookimpl
from toolkit.motion import facing_vector

__all__ = ["SyntheticVision", "line_of_sight_blocked"]


def line_of_sight_blocked(eye: np.ndarray, targets: np.ndarray, target_radii: np.ndarray,
                          centres: np.ndarray, radii: np.ndarray, *, same: np.ndarray | None = None) -> np.ndarray:
    """Which targets are hidden from ``eye`` by a nearer sphere.

    A target sphere is hidden when a nearer sphere covers the inner half of its
    radius as seen from the eye (a head is not hidden by the nose in front of it;
    a nose is hidden by a hand held over it).

    Parameters
    ----------
    eye : array (3,)
    targets : array (T, 3), target_radii : array (T,)
    centres : array (S, 3), radii : array (S,)
        Occluding spheres.
    same : array of bool (T, S), optional
        Pairs that must not occlude each other (a part and its own sphere).

    Returns
    -------
    array of bool (T,)
    """
    ray = targets - eye  # (T, 3)
    length = np.linalg.norm(ray, axis=1)
    u = ray / np.maximum(length, 1e-12)[:, None]
    rel = centres[None, :, :] - eye  # (1, S, 3)
    t = np.einsum("tk,tsk->ts", u, np.broadcast_to(rel, (len(targets), *rel.shape[1:])))  # along each ray
    closest = rel - t[..., None] * u[:, None, :]
    perp = np.linalg.norm(closest, axis=2)
    nearer = (t > 0) & (t < length[:, None] - 1e-9)  # the occluder's centre is nearer than the target's
    blocked = nearer & (perp < radii[None, :] - 0.5 * target_radii[:, None])  # the sphere's centre region is covered
    if same is not None:
        blocked &= ~same
    return blocked.any(axis=1)


class SyntheticVision(Perception):
    """Field of view, range and occlusion by parts and objects, with noise, dropouts and a sensory buffer (§4.2, §5.1)."""

    name = "synthetic-vision"
    parameters = (
        Parameter("eye", str, "head", "The observer's part its eye is at."),
        Parameter("fov", float, 140.0, "Horizontal and vertical field of view in degrees, around where the observer faces.",
                  minimum=1.0, maximum=360.0),
        Parameter("range", float, 20.0, "Farthest distance seen, metres.", minimum=0.0),
        Parameter("occlusion", bool, True, "Hide parts behind nearer parts and objects."),
        Parameter("part_radius", float, 0.03, "Radius (m) of each part's sphere, for occlusion.", minimum=0.0),
        Parameter("radii", dict, {}, "Per-part radius overrides, e.g. { left_hand = 0.045 }."),
        Parameter("noise", float, 0.0, "Standard deviation (m) of Gaussian noise on every seen position.", minimum=0.0),
        Parameter("dropout", float, 0.0, "Probability that a visible part is missed in a frame.", minimum=0.0, maximum=1.0),
        Parameter("buffer", float, 0.1, "Seconds the sensory buffer bridges a part's dropout (0: off).", minimum=0.0,
                  seconds=True),
        Parameter("facing_window", float, 3.0, "Seconds over which the target's facing is a running median "
                  "(steady through kicks and head turns; a real turn is followed after half of it), the forward "
                  "marker's side the vote of its frames (0: every frame on its own).", minimum=0.0, seconds=True),
        Parameter("seed", int, 0, "Seed of noise and dropouts."),
        *OBJECT_PARAMETERS,
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        owner.body.index(self.params["eye"], key=("eye",))
        for part, r in self.params["radii"].items():
            if isinstance(r, bool) or not isinstance(r, (int, float)) or r < 0:
                raise ConfigError(f"invalid radius {r!r}", key=("radii", part), expected="a radius in metres >= 0")
        self._facing: HeadingFilter | None = None  # made by reset(fps), when watching begins
        self._objects: ObjectTracker = tracker_for(self.params)  # checks the looks now, at the character's load

    def reset(self, fps: float) -> None:
        self._rng = np.random.default_rng(self.params["seed"])
        self._fps = float(fps)
        self._buffer: SensoryBuffer | None = None
        self._facing = HeadingFilter(round(self.params["facing_window"] * fps))
        self._objects = tracker_for(self.params, fps)  # a new stream: the objects are named afresh

    def _radii(self, body: Any) -> np.ndarray:
        """Sphere radius of every part; 0 for fingers, which are joint angles carried by a wrist, not places."""
        radii = np.full(body.n_parts, self.params["part_radius"])
        for part, r in self.params["radii"].items():
            if part in body.parts:
                radii[body.index(part)] = float(r)
        radii[body.angle_mask] = 0.0
        return radii

    @staticmethod
    def _places(body: Any, positions: np.ndarray) -> np.ndarray:
        """Where each part is in space: a finger (its values are joint angles) is where its wrist is."""
        return np.where(body.angle_mask[:, None], positions[body.carriers], positions)

    @staticmethod
    def _hand_percepts(body: Any, truth: np.ndarray, positions: np.ndarray, seen: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The hand percept carries the finger joint angles, seen whenever the wrist is (K&G §4.1)."""
        angles = body.angle_mask
        if not angles.any():
            return positions, seen
        seen = np.where(angles, seen[body.carriers], seen)
        return np.where(angles[:, None] & seen[:, None], truth, positions), seen

    def look(self, observer: Any, target: Any, world: Any) -> tuple[np.ndarray, np.ndarray, Detections]:
        """What the eye gets now, before noise and dropouts: the target's part positions (P, 3), which of them it
        sees (P,), and the objects it sees (:class:`~plugins.perception.object_tracking.Detections`: where, how big,
        what colour; never what the world calls them or what they are)."""
        truth = target.world_pose()
        positions = self._places(target.body, truth)
        eye = self.eye(observer)
        seen = self._in_view(eye, observer.heading, positions)
        shown = [o for o in world.objects.values() if o.held_by != observer.id]  # not what the observer holds itself
        centres = np.array([o.position for o in shown], dtype=float).reshape(-1, 3)
        sizes = np.array([o.radius for o in shown], dtype=float)
        objects_seen = self._in_view(eye, observer.heading, centres) if shown else np.zeros(0, dtype=bool)
        if self.params["occlusion"]:
            radii = self._radii(target.body)
            if seen.any():
                all_centres = np.concatenate([positions, centres])
                all_radii = np.concatenate([radii, sizes])
                same = np.zeros((len(positions), len(all_centres)), dtype=bool)
                same[np.arange(len(positions)), np.arange(len(positions))] = True
                seen &= ~line_of_sight_blocked(eye, positions, radii, all_centres, all_radii, same=same)
            if objects_seen.any():  # objects hidden behind the target's body
                objects_seen &= ~line_of_sight_blocked(eye, centres, sizes, positions, radii)
            if objects_seen.any() and len(shown) > 1:  # and behind other objects (a screen, a box)
                objects_seen &= ~line_of_sight_blocked(eye, centres, sizes, centres, sizes, same=np.eye(len(shown), dtype=bool))
        positions, seen = self._hand_percepts(target.body, truth, positions, seen)
        colours = np.array([rgb_of(o.colour) for o in shown], dtype=float).reshape(-1, 3)
        return positions, seen, Detections(centres[objects_seen].copy(), sizes[objects_seen].copy(),
                                           colours[objects_seen])

    def eye(self, observer: Any) -> np.ndarray:
        """Where the observer's eye is now (world, (3,))."""
        return observer.world_pose()[observer.body.index(self.params["eye"])]

    def _in_view(self, eye: np.ndarray, heading: float, points: np.ndarray) -> np.ndarray:
        ray = points - eye
        dist = np.linalg.norm(ray, axis=-1)
        forward = facing_vector(heading)
        cos = np.einsum("...i,i->...", ray, forward) / np.maximum(dist, 1e-12)
        half = np.radians(self.params["fov"]) / 2
        inside = cos >= np.cos(min(half, np.pi))
        return inside & (dist <= self.params["range"]) & np.isfinite(points).all(axis=-1)

    def perceive(self, observer: Any, target: Any, world: Any) -> Percept:
        if self._facing is None:
            raise RuntimeError("perceive before reset(fps): an observer resets its perception when it begins watching")
        positions, seen, detections = self.look(observer, target, world)
        p = self.params
        if p["noise"] > 0:
            positions = positions + self._rng.normal(0.0, p["noise"], positions.shape)
            detections.positions = detections.positions + self._rng.normal(0.0, p["noise"], detections.positions.shape)
        if p["dropout"] > 0:
            seen &= self._rng.random(len(seen)) >= p["dropout"]
        if self._buffer is None or len(self._buffer.last) != len(positions):
            self._buffer = SensoryBuffer(len(positions), int(round(p["buffer"] * self._fps)))
        positions, seen = self._buffer.update(positions, seen)
        # one frame (P, 3): the facing's running median takes this frame's estimate
        pose, mask, root, heading = root_relative(positions, seen, target.body, self._facing)
        objects, kinds, sizes = self._objects.update(detections)
        return Percept(world.time, pose, mask, np.where(seen[:, None], positions, np.nan), root, float(heading), objects,
                       kinds, sizes)

    def position_uncertainty(self, distance: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """The standard deviation (m) of a seen position at ``distance`` (m) from the eye, across the line of sight
        and along it: the Gaussian ``noise`` both ways (the geometric eye is otherwise exact)."""
        d = np.asarray(distance, dtype=float)
        sigma = np.full(d.shape, float(self.params["noise"]))
        return sigma, sigma.copy()

    def in_view(self, observer: Any, target: Any, world: Any, points: np.ndarray) -> np.ndarray:
        """Whether an object at each of ``points`` (n, 3) would be seen now: in the field of view and range, and
        (with ``occlusion``) not behind the target's body or an object, as :meth:`look` decides for the objects it
        sees."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        eye = self.eye(observer)
        seen = self._in_view(eye, observer.heading, points)
        if self.params["occlusion"] and seen.any():
            parts = self._places(target.body, target.world_pose())
            shown = [o for o in world.objects.values() if o.held_by != observer.id]
            centres = np.concatenate([parts, np.array([o.position for o in shown]).reshape(-1, 3)])
            radii = np.concatenate([self._radii(target.body), [o.radius for o in shown]])
            seen &= ~line_of_sight_blocked(eye, points, np.zeros(len(points)), centres, radii)
        return seen


@hookimpl
def likeme_register_perceptions():
    return [SyntheticVision]
