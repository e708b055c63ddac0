"""Action system ``imitation``: imitate a recognised movement by performing one's own.

Buchsbaum & Blumberg 2005, §5.3: once Max has identified Morris's movement as
one of his own, his action system requests *that* movement from his motor
system; he does not replay the observed path. Here every recognised movement
with enough confidence is imitated (queued if the character is busy).

Kopp & Graeser 2006, §4.4: a familiar movement demonstrated at another speed
re-parameterises the command in speed. When the matcher measured the
demonstration's speed relative to the command (``details["speed"]``, the
``forward-model`` does), the imitation is performed at that speed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plugins.lib.pose_distance import pose_distance
from toolkit import ActionSystem, Motion, MovementRequest, Parameter, hookimpl
from toolkit.motion import fill_hidden, local_to_world


class Imitation(ActionSystem):
    """Performs its own version of every movement it recognises (§5.3)."""

    name = "imitation"
    parameters = (
        Parameter("min_confidence", float, 0.0, "Imitate only matches at least this confident.", minimum=0.0, maximum=1.0),
        Parameter("speed", float, 1.0, "Playback speed of the imitation (times the demonstrator's, with follow_speed).",
                  minimum=0.01),
        Parameter("follow_speed", bool, True, "Perform at the speed the matcher measured in the demonstration "
                  "(a familiar movement at another speed, K&G §4.4)."),
    )

    def respond(self, actor, target, match, behaviour, world) -> MovementRequest | None:
        if not match.known or match.confidence < self.params["min_confidence"]:
            return None
        if match.movement not in actor.character.motor.movements():
            return None
        measured = float(match.details.get("speed", 1.0)) if self.params["follow_speed"] else 1.0
        return MovementRequest(
            match.movement,
            speed=self.params["speed"] * measured,
            reason=f"imitating {target.id}'s {match.movement}",
            imitating=target.id,
        )


# -- a recording imitated: what the observer performs, written out ---------------------------------------------------

@dataclass(frozen=True)
class ImitatedSegment:
    """One segment of the demonstration and what the observer performed for it.

    ``movement``: the movement performed (one of the repertoire, or one learned from this demonstration);
    ``learned``: the segment was unknown and was learned here (true imitation: B&B §7.3, K&G §4.3), and is
    performed as the demonstrator did it; ``start``/``end``: frames of the demonstration, end exclusive.
    """

    start: int
    end: int
    movement: str
    learned: bool
    confidence: float


@dataclass(frozen=True)
class RecordedImitation:
    """A demonstration imitated by an observer, frame for frame at the demonstrator's timing.

    ``motion``: the observer's world positions (frames, P, 3) in its own parts, at the demonstration's frame rate;
    ``segments``: what was performed where; ``learned``: each movement learned here with the clip it was learned
    from (the demonstrator's segment retargeted to the observer's body, world positions), to be saved as a new
    folder of a repertoire.
    """

    motion: Motion
    segments: tuple[ImitatedSegment, ...]
    learned: dict[str, Motion]
    demonstration: Motion


class MovementPerformer:
    """A recognised movement performed by the motor system's own ``perform`` (any motor system)."""

    def __init__(self, motor: Any) -> None:
        self.motor = motor

    def local(self, movement: str, match: Any, fps: float) -> np.ndarray:
        """The movement's local-frame poses (frames, P, 3), hidden parts held."""
        return self.motor.perform(movement, fps=fps).filled().positions


class TakePerformer(MovementPerformer):
    """A recognised movement performed along the take of it whose nodes the matched path shares most (a posegraph:
    its ``paths`` hub to hub, B&B §4.1), so that of several clips of one movement the one nearest the demonstration
    is played; a movement the matched path does not reach is performed as the motor system performs it."""

    def local(self, movement: str, match: Any, fps: float) -> np.ndarray:
        matched = set(match.path) if match is not None and match.path else set()
        labels = self.motor.paths_label
        takes = [path for name, path in self.motor.paths.items() if labels.get(name) == movement]
        if not takes or not matched:
            return super().local(movement, match, fps)
        best = max(takes, key=lambda path: len(matched.intersection(path)))
        return self.motor.play_path(best, fps=fps).filled().positions


def performer_for(motor: Any) -> MovementPerformer:
    """The performer a motor system allows (chosen once): :class:`TakePerformer` for a graph of paths."""
    return TakePerformer(motor) if all(hasattr(motor, k) for k in ("paths", "paths_label", "play_path")) \
        else MovementPerformer(motor)


def time_warp(poses: np.ndarray, n: int) -> np.ndarray:
    """Poses (K, P, 3) played over ``n`` frames: linear interpolation at evenly spaced times, first and last kept
    (the command re-parameterised in speed to the demonstrated duration, K&G §4.4)."""
    poses = np.asarray(poses, dtype=float)
    if len(poses) == 1 or n == 1:
        return np.repeat(poses[:1], n, axis=0) if n == 1 or len(poses) == 1 else poses
    t = np.linspace(0.0, len(poses) - 1.0, n)
    i = np.minimum(t.astype(int), len(poses) - 2)
    w = (t - i)[:, None, None]
    return poses[i] * (1.0 - w) + poses[i + 1] * w


class Duration:
    """Timing ``duration`` (the papers'): the performed movement played evenly over the demonstrated segment, its
    speed re-parameterised to the segment's duration (K&G §4.4)."""

    name = "duration"

    def timed(self, performed: np.ndarray, demonstrated: np.ndarray) -> np.ndarray:
        return time_warp(performed, len(demonstrated))


class Aligned:
    """Timing ``aligned``: the performed movement time-warped onto the demonstrated segment pose by pose (dynamic time
    warping of the root-relative poses, :func:`dtaidistance.dtw_ndim.warping_path`), so that it is quick where the
    demonstrator was quick and holds where they held; each demonstrated frame gets the mean of the performed frames
    matched to it."""

    name = "aligned"

    def timed(self, performed: np.ndarray, demonstrated: np.ndarray) -> np.ndarray:
        from dtaidistance import dtw_ndim

        n = len(demonstrated)
        a = np.ascontiguousarray(demonstrated.reshape(n, -1), dtype=np.double)
        b = np.ascontiguousarray(performed.reshape(len(performed), -1), dtype=np.double)
        path = np.array(dtw_ndim.warping_path(a, b))
        sums = np.zeros((n, *performed.shape[1:]))
        np.add.at(sums, path[:, 0], performed[path[:, 1]])
        counts = np.bincount(path[:, 0], minlength=n)[:, None, None]
        return sums / np.maximum(counts, 1)


TIMINGS = {"duration": Duration, "aligned": Aligned}
"""The timing strategies by name."""


def blend_joins(local: np.ndarray, starts: list[int], frames: int) -> np.ndarray:
    """Each piece starting at a frame of ``starts`` joined to the pose before it: the jump between them spread over
    the piece's first ``frames`` frames, fading linearly (the poses stay continuous; the timing does not change)."""
    out = local.copy()
    for s in starts:
        if s <= 0 or s >= len(out):
            continue
        jump = out[s - 1] - out[s]
        k = min(frames, len(out) - s)
        fade = (1.0 - np.arange(1, k + 1) / (k + 1))[:, None, None]
        out[s : s + k] += jump * fade
    return out


def imitate_motion(observer: Any, demonstration: Motion, *, transition: float = 0.2,
                   timing: Duration | Aligned | None = None) -> RecordedImitation:
    """The demonstration watched, recognised and performed by the observer with its own movements.

    Buchsbaum & Blumberg 2005, §5.3 and Kopp & Graeser 2006, §4.4: every segment the observer's segmenter closes and
    its matcher recognises is performed as its own movement (its repertoire's take, :func:`performer_for`), time
    warped to the segment's duration (``timing``: :class:`Duration`, the default, or :class:`Aligned`); between segments it stands in the hub it is nearest (all
    movements begin and end in a hub, §4.1), and each join is blended over ``transition`` seconds
    (:func:`blend_joins`). A segment that is unknown is learned when the matcher learns (``learn = true``: B&B §7.3,
    K&G §4.3): the first time it is performed as the demonstrator did it (their poses as the observer perceived
    them, through its correspondence, if it has one: retargeted to its own body), after that as the learned
    movement. An unknown segment the matcher does not learn is left in the hub.

    The body travels and turns as the demonstrator's root did, the displacement scaled by the observer's standing
    root height over theirs. ``observer``: a :class:`toolkit.observe.Observer` (its character's motor system
    performs); the motion is world positions of its body's parts, in metres, +y up.
    """
    character, body = observer.character, observer.body
    motor = character.motor
    known_before = set(motor.movements())
    observations = observer.watch(demonstration)
    perceived = fill_hidden(np.asarray(observer.poses, dtype=float), np.asarray(observer.visible, dtype=bool),
                            np.zeros((body.n_parts, 3)))
    n, fps, root = demonstration.n_frames, demonstration.fps, body.root_index
    hubs = np.asarray(motor.hub_poses(), dtype=float)
    rest = np.asarray(motor.rest_pose(), dtype=float)
    lift = rest[root]  # local frame: the root at its standing height
    performer = performer_for(motor)
    timing = timing if timing is not None else Duration()
    local = np.repeat(rest[None], n, axis=0)
    pieces, segments, learned = [], [], {}
    for o in observations:
        s, e = o.segment.start, min(o.segment.end, n)
        movement = o.movement
        if movement is None:
            continue
        first = movement not in known_before and movement not in learned
        if first:  # performed as the demonstrator did it, as the observer perceived (and mapped) them
            poses = perceived[s:e] - perceived[s:e, root : root + 1] + lift
            learned[movement] = poses
        else:
            seen = perceived[s:e] - perceived[s:e, root : root + 1] + lift
            poses = timing.timed(performer.local(movement, o.match, fps), seen)
        local[s:e] = poses
        pieces.append((s, e))
        segments.append(ImitatedSegment(s, e, movement, first, float(o.match.confidence) if o.match else 0.0))
    for k, (s, e) in enumerate(pieces):  # the gaps: the hub nearest the pose before (the first: the pose after)
        gap_end = pieces[k + 1][0] if k + 1 < len(pieces) else n
        if e < gap_end:
            local[e:gap_end] = hubs[np.argmin(pose_distance(hubs, local[e - 1]))]
    if pieces and pieces[0][0] > 0:
        local[: pieces[0][0]] = hubs[np.argmin(pose_distance(hubs, local[pieces[0][0]]))]
    joins = sorted({s for s, _ in pieces} | {e for _, e in pieces})
    local = blend_joins(local, joins, max(1, int(round(transition * fps))))
    world = _placed(local, demonstration, body, lift)
    learned_world = {name: Motion(world_clip, fps, body.parts) for name, world_clip in
                     ((name, _learned_world(poses, lift)) for name, poses in learned.items())}
    return RecordedImitation(Motion(world, fps, body.parts), tuple(segments), learned_world, demonstration)


def _learned_world(poses: np.ndarray, lift: np.ndarray) -> np.ndarray:
    """A learned clip's local poses (root lifted to standing height) as world positions at the origin, feet on the
    floor: what a repertoire folder holds."""
    return poses - np.array([lift[0], 0.0, lift[2]])


def _placed(local: np.ndarray, demonstration: Motion, body: Any, lift: np.ndarray) -> np.ndarray:
    """Local-frame poses placed where the demonstrator's root is and turned as they face (a centred running median
    of the facing over one second, held where it cannot be found); their displacement from where they began scaled
    by the observer's standing root height over theirs, so that a smaller body takes smaller steps."""
    from plugins.lib.root_frame import RecordingFacing, root_relative

    window = max(1, int(round(demonstration.fps)))
    _, _, root_world, heading = root_relative(demonstration.positions, demonstration.visible, body,
                                              RecordingFacing(window))
    heading, root_world = _held(heading), _held(root_world)
    seen = np.where(demonstration.visible[..., None], demonstration.positions, np.nan)[..., 1]
    floor = float(np.nanmin(seen)) if np.isfinite(seen).any() else 0.0
    middle = float(np.median(root_world[:, 1]))
    scale = float(lift[1] / (middle - floor)) if middle - floor > 1e-6 and lift[1] > 1e-6 else 1.0
    target = root_world[0] + (root_world - root_world[0]) * scale
    target[:, 1] = lift[1] + scale * (root_world[:, 1] - middle)  # the observer's feet on the floor, y = 0
    return local_to_world(local - lift, target, heading)


def _held(values: np.ndarray) -> np.ndarray:
    """Values (F, ...) with non-finite rows replaced by the last finite one (the first finite one before it); zero
    when none is finite."""
    values = np.asarray(values, dtype=float)
    ok = np.isfinite(values.reshape(len(values), -1)).all(axis=1)
    if not ok.any():
        return np.zeros_like(values)
    index = np.where(ok, np.arange(len(values)), 0)
    np.maximum.accumulate(index, out=index)
    index[: np.argmax(ok)] = np.argmax(ok)
    return values[index]


def imitation_error(imitation: Motion, demonstration: Motion, body: Any, frames: np.ndarray | None = None) -> float:
    """How far the imitation's poses are from the demonstrator's: the mean over frames of eq. 1 (the mean distance
    of the visible parts) between their root-relative poses in each body's own frame (B&B §5.1: position and facing
    aligned), in the observer's body sizes (:func:`plugins.lib.body_size.body_scale` of its first frame).
    ``frames``: a boolean mask of the frames measured (default every frame)."""
    from plugins.lib.body_size import body_scale
    from plugins.lib.root_frame import RecordingFacing, root_relative

    def rel(m: Motion) -> tuple[np.ndarray, np.ndarray]:
        window = max(1, int(round(m.fps)))
        poses, seen, _, _ = root_relative(m.positions, m.visible, body, RecordingFacing(window))
        return poses, seen

    a, seen_a = rel(imitation)
    b, seen_b = rel(demonstration)
    d = pose_distance(np.nan_to_num(a), np.nan_to_num(b), seen_a & seen_b)
    if frames is not None:
        d = d[np.asarray(frames, dtype=bool)]
    size = float(body_scale(imitation.positions[0] - imitation.positions[0, body.root_index]))
    return float(np.nanmean(d) / size) if size > 0 and np.isfinite(d).any() else float("nan")


@hookimpl
def likeme_register_action_systems():
    return [Imitation]
