"""Takes joined into one stream as a person performs them one after another (the Bandai-Namco streams, issue 36).

A recorded take is cropped: it may begin and end in mid-movement, in its own place and facing. Joined end to end,
takes make a stream with jumps that no person makes. The functions here join takes through what a person does
between two takes instead, on the BVH channels (so any skeleton with a root that has position and rotation channels
will do; +y up, as BVH has it):

- :func:`at_rest`: whether a take begins and ends at rest: over its first and its last ``REST_WINDOW`` seconds
  every joint stays within ``REST_RADIUS`` body sizes of where it is on average (positions relative to the joints'
  centroid, so walking in place is not rest; the body size is :func:`plugins.lib.body_size.body_scale`). 0.3 s is a
  pause people make between gestures (three of Kopp & Graeser's sensory memories, §4.1); 0.05 body sizes (about
  2.5 cm on an adult) is half of Buchsbaum & Blumberg's hub threshold (0.1 body sizes, §5.1), the most that
  ``hub-threshold`` lets standing sway and noise be (its ``cap``). And it must move in between: some joint
  ``MOVES`` (0.2) body sizes or farther from where it began (two of the Bandai-Namco takes at rest at both ends,
  byebye in the feminine and the not-confident style, move no joint farther than 0.09 body sizes, 4 cm; the others
  0.4 or more).
- :func:`placed`: a take moved so that it begins where the take before it ended (the centroid over the floor) and
  turned about the vertical so that its first pose faces the way the last pose did (the yaw that best aligns the two
  poses' joints over the floor, a least-squares fit in closed form).
- :func:`transition`: the channels from one pose to another in ``frames`` frames with a minimum-jerk profile
  (``10u^3 - 15u^4 + 6u^5``, Flash & Hogan 1985): position channels interpolated, each joint's rotation slerped,
  the body's centroid on the straight line between the two.
- :func:`join`: takes one after another; before each (after the first) the last pose held, the transition (at a pace
  a person keeps when they change stance: no joint faster than a body size a second on average), the next take's
  first pose held. The true segments are the takes' own frames.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from toolkit import ConfigError

__all__ = ["REST_WINDOW", "REST_RADIUS", "at_rest", "placed", "transition", "join", "minimum_jerk"]

REST_WINDOW = 0.3
"""Seconds at a take's beginning and end over which :func:`at_rest` looks."""
REST_RADIUS = 0.05
"""Body sizes every joint stays within (of its mean over ``REST_WINDOW``) for :func:`at_rest`."""
MOVES = 0.2
"""Body sizes (about 10 cm on an adult) some joint must go from where it began for :func:`at_rest` to take a take
as a movement at all."""


def _centred(positions: np.ndarray) -> np.ndarray:
    """Joint positions (F, J, 3) relative to each frame's centroid of the joints."""
    return positions - positions.mean(axis=1, keepdims=True)


def at_rest(bvh, window: float = REST_WINDOW, radius: float = REST_RADIUS, moves: float = MOVES) -> bool:
    """Whether the take ``bvh`` begins and ends at rest (see the module): over its first and last ``window``
    seconds no joint moves farther than ``radius`` body sizes from its mean there; and moves in between (some joint
    goes farther than ``moves`` body sizes from where it was in the first frame: a take that hardly moves is at rest
    throughout, not a gesture)."""
    from plugins.lib.body_size import body_scale

    frames = max(2, int(round(window * bvh.fps)))
    if bvh.n_frames < 2 * frames:
        return False
    positions = bvh.positions()
    ends = _centred(np.concatenate([positions[:frames], positions[-frames:]]))
    size = float(np.median(body_scale(ends)))
    if not size > 0:
        return False
    for part in (ends[:frames], ends[frames:]):
        if np.linalg.norm(part - part.mean(axis=0), axis=-1).max() > radius * size:
            return False
    centred = _centred(positions)
    return bool(np.linalg.norm(centred - centred[:1], axis=-1).max() > moves * size)


def _roots(bvh) -> list[tuple[int, np.ndarray, np.ndarray, str]]:
    """Each root joint's (index, position columns (3,), rotation columns (3,), rotation order); a root without three
    position and three rotation channels cannot be placed."""
    out, start = [], 0
    for j, joint in enumerate(bvh.joints):
        columns = np.arange(start, start + len(joint.channels))
        start += len(joint.channels)
        if joint.parent >= 0:
            continue
        position = [c for c, name in zip(columns, joint.channels) if name.endswith("position")]
        rotation = [c for c, name in zip(columns, joint.channels) if name.endswith("rotation")]
        if len(position) != 3 or len(rotation) != 3:
            raise ConfigError(f"root joint {joint.name!r} has channels {list(joint.channels)}", file=bvh.source,
                              expected="three position and three rotation channels on every root joint (a take is "
                                       "moved and turned through them)")
        order = "".join(joint.channels[list(columns).index(c)][0] for c in rotation)
        names = [joint.channels[list(columns).index(c)][0] for c in position]
        out.append((j, np.array(position)[np.argsort(names)], np.array(rotation), order))
    return out


def _rotations(bvh) -> list[tuple[np.ndarray, str]]:
    """Every joint's rotation columns and their order (joints with none left out)."""
    out, start = [], 0
    for joint in bvh.joints:
        columns = np.arange(start, start + len(joint.channels))
        start += len(joint.channels)
        rotation = [(c, name[0]) for c, name in zip(columns, joint.channels) if name.endswith("rotation")]
        if rotation:
            out.append((np.array([c for c, _ in rotation]), "".join(axis for _, axis in rotation)))
    return out


def _pose(bvh, values: np.ndarray) -> np.ndarray:
    """World joint positions (J, 3) of one frame of channel values."""
    from toolkit.bvh import BVH

    return BVH(bvh.joints, bvh.frame_time, values[None], bvh.source).positions()[0]


def placed(bvh, values: np.ndarray, after: np.ndarray) -> np.ndarray:
    """The channel values (F, C) of the take ``bvh`` (its joints) moved and turned so that its first frame stands
    where the pose ``after`` (world joint positions (J, 3), the last pose of the take before) stands and faces its
    way: a turn about the vertical by the angle that best aligns the two poses' centroid-relative joints over the
    floor, and a shift of the centroid over the floor."""
    from scipy.spatial.transform import Rotation

    values = np.array(values, dtype=float)
    first = _pose(bvh, values[0])
    a, b = after - after.mean(axis=0), first - first.mean(axis=0)
    # the yaw t maximising sum a . Ry(t) b over the floor (x, z): Ry(t) maps (x, z) to (x cos t + z sin t, -x sin t +
    # z cos t), so the sum is cos t * (xa xb + za zb) + sin t * (xa zb - za xb)
    sine, cosine = (a[:, 0] * b[:, 2] - a[:, 2] * b[:, 0]).sum(), (a[:, 0] * b[:, 0] + a[:, 2] * b[:, 2]).sum()
    yaw = float(np.arctan2(sine, cosine))
    turn = Rotation.from_euler("y", yaw)
    centre = first.mean(axis=0) * [1.0, 0.0, 1.0]
    target = after.mean(axis=0) * [1.0, 0.0, 1.0]
    for _, position, rotation, order in _roots(bvh):
        values[:, position] = turn.apply(values[:, position] - centre) + target
        values[:, rotation] = (turn * Rotation.from_euler(order, values[:, rotation], degrees=True)).as_euler(
            order, degrees=True)
    return values


def minimum_jerk(frames: int) -> np.ndarray:
    """The share of the way done at each of ``frames`` frames strictly between two poses (frames,): ``10u^3 -
    15u^4 + 6u^5`` at ``u = k / (frames + 1)``, zero speed and acceleration at both ends."""
    u = np.arange(1, frames + 1) / (frames + 1)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u**2)


def transition(bvh, start: np.ndarray, end: np.ndarray, frames: int) -> np.ndarray:
    """``frames`` frames of channel values (frames, C) from the frame ``start`` to the frame ``end`` (C,) exclusive,
    minimum-jerk in time: position channels interpolated, each joint's rotation slerped (the shortest way), and the
    roots shifted so that the joints' centroid goes straight from where it is in ``start`` to where it is in
    ``end`` (a root's turn would otherwise swing a body that stands far from the root's origin along an arc)."""
    from scipy.spatial.transform import Rotation, Slerp

    from toolkit.bvh import BVH

    share = minimum_jerk(frames)
    out = start[None] + share[:, None] * (end - start)[None]  # the position channels (rotations replaced below)
    for columns, order in _rotations(bvh):
        ends = Rotation.from_euler(order, np.stack([start[columns], end[columns]]), degrees=True)
        out[:, columns] = Slerp([0.0, 1.0], ends)(share).as_euler(order, degrees=True).reshape(frames, -1)
    if frames:
        a, b = _pose(bvh, start).mean(axis=0), _pose(bvh, end).mean(axis=0)
        off = a[None] + share[:, None] * (b - a)[None] - BVH(bvh.joints, bvh.frame_time, out).positions().mean(axis=1)
        for _, position, _, _ in _roots(bvh):
            out[:, position] += off
    return out


def join(bvh_takes: Sequence, labels: Sequence[str], holds: Sequence[tuple[int, int]], moves: Sequence[int],
         lead: int = 0, tail: int = 0, pace: float = 0.0) -> tuple[np.ndarray, list[tuple[int, int, str]]]:
    """Takes (BVH, one skeleton) one after another: the channel values of the stream (F, C) and its true segments
    (start, end exclusive, label), one a take.

    Before take ``k`` (k >= 1) the last pose of take ``k - 1`` is held ``holds[k - 1][0]`` frames, the transition to
    take ``k``'s first pose (the take :func:`placed` after it) lasts ``moves[k - 1]`` frames, or longer with
    ``pace`` > 0: long enough that the joint that goes farthest covers no more than ``pace`` body sizes a second on
    average (:func:`plugins.lib.body_size.body_scale` of the pose it leaves), and that pose is held
    ``holds[k - 1][1]`` frames; ``lead`` frames of the first pose begin the stream and ``tail`` frames of the last
    end it."""
    from plugins.lib.body_size import body_scale

    first = bvh_takes[0]
    pieces = [np.repeat(first.values[:1], lead, axis=0), first.values]
    rows, at = [(lead, lead + first.n_frames, labels[0])], lead + first.n_frames
    last = first.values[-1]
    for k in range(1, len(bvh_takes)):
        take = bvh_takes[k]
        leaving = _pose(first, last)
        values = placed(first, take.values, leaving)
        before, after = holds[k - 1]
        frames = moves[k - 1]
        if pace > 0:
            far = float(np.linalg.norm(_pose(first, values[0]) - leaving, axis=1).max())  # the farthest way
            seconds = far / (pace * max(float(body_scale(leaving)), 1e-9))
            frames = max(frames, int(np.ceil(seconds / first.frame_time)))
        between = [np.repeat(last[None], before, axis=0), transition(first, last, values[0], frames),
                   np.repeat(values[:1], after, axis=0)]
        pieces += [*between, values]
        at += sum(len(p) for p in between)
        rows.append((at, at + len(values), labels[k]))
        at += len(values)
        last = values[-1]
    pieces.append(np.repeat(last[None], tail, axis=0))
    return np.concatenate(pieces), rows
