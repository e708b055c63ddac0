"""Layer ``look-at``: a character turns its head toward what it attends to (Buchsbaum & Blumberg 2005, §6.1.2).

The action system's object of attention (the ``object`` of the :class:`~toolkit.components.MovementRequest` it
returns) is where the character looks while it performs the movement: the head and the parts that turn with it
(the nose; the eyes, where a body has them) rotate rigidly about the pivot joint (the head itself, or a neck) so
that the gaze line (head to nose) points at the object, clamped to the yaw and pitch limits, blended in at the
movement's start and out at its end. An observer then reads the character's line of sight from the head and nose
it perceives (:func:`plugins.action.behaviour_identification.line_of_sight`), wherever the object lies.

Angles are in the character's local frame (+z where it faces, +x to its left, +y up): *yaw* is the horizontal
angle from +z, positive to the left; *pitch* is the angle above the horizontal. The limits hold for where the gaze
ends up, relative to the character's facing (+z), not for how far it turns from the motion's own head pose. The
turn is blended with the weight ``w(t) = s(t / blend_in) * s((T - t) / blend_out)``, ``s`` the smoothstep
``3x^2 - 2x^3`` on [0, 1] and ``T`` the movement's length, so the first and last frames of every movement are the
motion's own: the hub the motor system starts and ends in is untouched. Without an object of attention, or for an
imitation or the way back from a stopped one, nothing changes.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

import numpy as np

from toolkit import ConfigError, Layer, Parameter, hookimpl
from toolkit.motion import world_to_local

__all__ = ["LookAt", "blend_weight", "gaze_angles", "turn", "look_at"]

_UP = np.array([0.0, 1.0, 0.0])


def blend_weight(t: float | np.ndarray, duration: float, blend_in: float, blend_out: float) -> np.ndarray:
    """How much of the turn is applied at time ``t`` (s) of a movement lasting ``duration`` (s), in [0, 1].

    ``s(t / blend_in) * s((duration - t) / blend_out)`` with ``s`` the smoothstep clipped to [0, 1]; a blend time
    of 0 is a step (full weight at once). 0 at ``t = 0`` and at ``t = duration`` when both blend times are
    positive.
    """
    t = np.asarray(t, dtype=float)

    def ramp(x: np.ndarray, span: float) -> np.ndarray:
        if span <= 0:
            return np.where(x >= 0, 1.0, 0.0)
        x = np.clip(x / span, 0.0, 1.0)
        return x * x * (3.0 - 2.0 * x)

    return ramp(t, blend_in) * ramp(duration - t, blend_out)


def gaze_angles(direction: np.ndarray) -> tuple[float, float]:
    """(yaw, pitch) in radians of a direction (3,) in the local frame: yaw from +z toward +x, pitch above the ground."""
    x, y, z = (float(v) for v in direction)
    return float(np.arctan2(x, z)), float(np.arctan2(y, np.hypot(x, z)))


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix (3, 3) about the unit ``axis`` by ``angle`` (right hand), Rodrigues' formula."""
    k = np.asarray(axis, dtype=float)
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * (cross @ cross)


def turn(pose: np.ndarray, pivot: int, parts: np.ndarray, heading: np.ndarray, yaw: float, pitch: float) -> np.ndarray:
    """``pose`` (P, 3) with ``parts`` rotated rigidly about the pivot part: first ``pitch`` up about the horizontal
    axis across ``heading`` (the gaze's horizontal direction), then ``yaw`` to the left about the vertical.

    A gaze of yaw ``a`` and pitch ``p`` (``|p + pitch| <= 90`` degrees) comes out at yaw ``a + yaw`` and pitch
    ``p + pitch``. The other parts are returned as they are.
    """
    h = np.array([heading[0], 0.0, heading[2]], dtype=float)
    h /= np.linalg.norm(h)
    across = np.cross(h, _UP)  # the axis about which +pitch lifts the gaze
    rotation = _rotation(_UP, yaw) @ _rotation(across, pitch)
    out = np.array(pose, dtype=float, copy=True)
    centre = out[pivot]
    out[parts] = (out[parts] - centre) @ rotation.T + centre
    return out


def look_at(pose: np.ndarray, target: np.ndarray, *, pivot: int, parts: np.ndarray, gaze: tuple[int, int],
            yaw_limit: float, pitch_up: float, pitch_down: float, weight: float = 1.0
            ) -> tuple[np.ndarray, float, float]:
    """Turn the head of ``pose`` (P, 3) toward ``target`` (3,), both in the local frame.

    The gaze (from part ``gaze[0]`` to ``gaze[1]``) is aimed at ``target`` as seen from ``gaze[0]``, clamped to
    ``|yaw| <= yaw_limit`` and ``-pitch_down <= pitch <= pitch_up`` (radians, relative to the local frame), and
    ``weight`` (0..1) of that turn is applied. Returns the new pose and the yaw and pitch turned (radians).
    Nothing turns (the pose is returned as given, with zero angles) when the gaze or the direction to the target
    has no horizontal length.
    """
    pose = np.asarray(pose, dtype=float)
    start, end = pose[gaze[0]], pose[gaze[1]]
    line, to = end - start, np.asarray(target, dtype=float) - start
    if np.hypot(line[0], line[2]) < 1e-9 or np.hypot(to[0], to[2]) < 1e-9 or weight <= 0:
        return pose, 0.0, 0.0
    yaw0, pitch0 = gaze_angles(line)
    yaw1, pitch1 = gaze_angles(to)
    yaw1 = float(np.clip(yaw1, -yaw_limit, yaw_limit))
    pitch1 = float(np.clip(pitch1, -pitch_down, pitch_up))
    d_yaw = float((yaw1 - yaw0 + np.pi) % (2 * np.pi) - np.pi) * weight
    d_pitch = (pitch1 - pitch0) * weight
    return turn(pose, pivot, parts, line, d_yaw, d_pitch), d_yaw, d_pitch


class LookAt(Layer):
    """Turns the head (and nose, eyes) toward the object of attention over every movement, clamped and blended."""

    name = "look-at"
    parameters = (
        Parameter("enabled", bool, True, "Turn the head at all (false: every movement as the motor system made it)."),
        Parameter("pivot", str, "head", "The joint the head turns about (the head itself, or a neck)."),
        Parameter("parts", list, ["nose"], "The parts that turn with the head about the pivot: the head when the "
                  "pivot is a neck, the nose, the eyes.", items=str),
        Parameter("gaze", list, ["head", "nose"], "Two parts whose line is where the character looks (from, to).",
                  items=str),
        Parameter("yaw", float, 70.0, "Furthest the gaze turns to either side of where the body faces, degrees.",
                  minimum=0.0, maximum=89.0),
        Parameter("pitch_up", float, 35.0, "Furthest the gaze lifts above the horizontal, degrees.",
                  minimum=0.0, maximum=89.0),
        Parameter("pitch_down", float, 45.0, "Furthest the gaze drops below the horizontal, degrees.",
                  minimum=0.0, maximum=89.0),
        Parameter("blend_in", float, 0.3, "Seconds over which the turn blends in at the start of a movement.",
                  minimum=0.0, maximum=60.0),
        Parameter("blend_out", float, 0.3, "Seconds over which it blends out before the movement's end.",
                  minimum=0.0, maximum=60.0),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        body = owner.body
        angles = [p for p, a in zip(body.parts, body.angle_mask) if a]
        positional = [p for p in body.parts if p not in angles]

        def index(name: Any, key: tuple) -> int:
            if name not in positional:
                raise ConfigError(f"unknown part {name!r}", key=key, expected="a positional part of the body",
                                  available=positional)
            return body.index(name)

        self._pivot = index(self.params["pivot"], ("pivot",))
        if not self.params["parts"]:
            raise ConfigError("no parts to turn", key=("parts",), expected="at least one part (the nose, the eyes)",
                              available=positional)
        self._parts = np.array([index(p, ("parts", i)) for i, p in enumerate(self.params["parts"])], dtype=int)
        gaze = self.params["gaze"]
        if len(gaze) != 2 or gaze[0] == gaze[1]:
            raise ConfigError(f"invalid gaze {list(gaze)!r}", key=("gaze",),
                              expected="two different parts [from, to] (head and nose)", available=positional)
        self._gaze = (index(gaze[0], ("gaze", 0)), index(gaze[1], ("gaze", 1)))
        if self._gaze[1] not in self._parts and self._gaze[1] != self._pivot:
            raise ConfigError(f"the gaze's end {gaze[1]!r} does not turn", key=("gaze", 1),
                              expected="a part of parts (it turns with the head)", available=list(self.params["parts"]))
        self._last: dict[str, Any] = {"object": None, "weight": 0.0, "yaw": 0.0, "pitch": 0.0}

    def weight(self, frame: int, n_frames: int, fps: float) -> float:
        """The blend weight at ``frame`` of a movement of ``n_frames`` frames at ``fps`` (:func:`blend_weight`)."""
        return float(blend_weight(frame / fps, (n_frames - 1) / fps, self.params["blend_in"], self.params["blend_out"]))

    def apply(self, actor: Any, request: Any, motion: Any, frame: int, world: Any) -> np.ndarray | None:
        obj = world.objects.get(request.object) if request.object is not None else None
        if not self.params["enabled"] or obj is None or request.imitating is not None:
            self._last = {"object": None, "weight": 0.0, "yaw": 0.0, "pitch": 0.0}
            return None
        w = self.weight(frame, motion.n_frames, motion.fps)
        target = world_to_local(obj.position, actor.position, actor.heading)
        pose, yaw, pitch = look_at(
            motion.positions[frame], target, pivot=self._pivot, parts=self._parts, gaze=self._gaze,
            yaw_limit=np.radians(self.params["yaw"]), pitch_up=np.radians(self.params["pitch_up"]),
            pitch_down=np.radians(self.params["pitch_down"]), weight=w)
        self._last = {"object": request.object, "weight": w, "yaw": float(np.degrees(yaw)),
                      "pitch": float(np.degrees(pitch))}
        return pose

    def inspect(self) -> Any:
        """The last frame's turn: the object looked at, the blend weight, the yaw and pitch turned (degrees)."""
        return MappingProxyType(dict(self._last))

    def describe(self) -> dict[str, Any]:
        return {"enabled": self.params["enabled"], "turns": [self.params["pivot"], *self.params["parts"]],
                "yaw": self.params["yaw"], "pitch": [-self.params["pitch_down"], self.params["pitch_up"]]}


@hookimpl
def likeme_register_layers():
    return [LookAt]
