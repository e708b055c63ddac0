"""What a matcher compares: a demonstration's frames against one's own, frame by frame (the *comparison*).

A matcher is a comparison, a search and a decision (``docs/matchers.md``). The comparison turns a sequence of
root-relative poses into *frames* (:class:`Frames`) and gives the distance of every frame of one sequence to every
frame of another (:meth:`Comparison.costs`); the search aligns the two sequences through time, and the decision
says whether the best alignment is near enough to be a known movement. Two comparisons, chosen once, when a matcher
is attached (``comparison = "poses"`` or ``"motion"``):

:class:`Poses` (the papers)
    Buchsbaum & Blumberg 2005, §5.1, eq. 1: the mean over the parts seen of the Euclidean distance between the two
    root-relative positions of each part (eq. 2), in metres. Where a hand is held is what counts; how it moves is
    seen only through the sequence of places.

:class:`Motion` (real people, the observer template's)
    Each part is seen by *where it goes*, *how it moves* and *how the body carries it*, in the demonstrator's own
    body sizes, so that a tall and a short performer, a stooped and an upright one, compare alike:

    - **shape**: the part's position about its own mean over the sequence (the held posture removed: a stoop, a hand
      held higher through a wave cancel; the excursion of the movement stays), over the body size;
    - **motion**: the part's velocity relative to the root in the body's frame, times :data:`HORIZON` seconds, over
      the body size: the displacement it is making. What tells a wave from a raise of the same hand is this: the
      reversals of a wave, which positions barely show. The velocity is a Savitzky-Golay derivative
      (:mod:`plugins.lib.velocity`), so a tracker's frame-to-frame jitter does not pass for motion;
    - **carry**: where the body goes and where it turns, which root-relative coordinates (§5.1) leave out and which
      move every part alike: the root's velocity in the body's own frame times :data:`HORIZON` over the body size
      (a walk forward, backward, sideways; a run), and the turn since the sequence began as the chord
      ``(cos θ - 1, sin θ)`` a point one body size ahead of the root moves along (a walk that turns left or right).

    The distance of two frames is eq. 1 over these with the root of the mean square in place of the mean: the root
    of the mean, over the parts seen in both, of the squared Euclidean norm of each part's difference in shape,
    motion and carry together (every part is carried by the body, so the carry enters each part's norm). The root
    mean square lets the parts that differ most, the ones that move, count most, where eq. 1's plain mean lets the
    many still parts of a whole body outweigh a waving hand; and it is a few matrix products for all frame pairs at
    once. Unit-free: one body size is 1. Nothing in it depends on the frame rate, which is taken out by the
    derivative, nor on the tempo, which the search's time warping takes up.

:data:`HORIZON` is 0.25 s: motion and shape count alike for a part swinging at ``1 / (2π · 0.25 s)``, about
0.64 Hz, the middle of the frequencies of human gestures and steps (half a hertz to a few hertz), so neither
outweighs the other for any of them. It was not chosen on data (``docs/matchers.md``).
"""

from __future__ import annotations

import warnings
from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar, NamedTuple

import numpy as np

from plugins.lib.body_size import body_scale
from plugins.lib.compiled import kernel
from plugins.lib.jitter import feature_noise, jitter_about_root
from plugins.lib.root_frame import RecordingFacing, root_relative
from plugins.lib.travel import body_velocity, turned
from plugins.lib.velocity import derivative

__all__ = ["COMPARISONS", "Comparison", "Fixed", "Frames", "HORIZON", "Motion", "Paired", "Poses", "Split", "comparison",
           "sequence_size"]

HORIZON = 0.25
"""Seconds over which a velocity counts as a displacement (the motion and the travel of :class:`Motion`)."""

@dataclass(frozen=True)
class Frames:
    """A sequence as a comparison sees it.

    Attributes
    ----------
    parts : array, shape (n, P, D)
        Each part's features per frame (:class:`Poses`: its position, D = 3; :class:`Motion`: shape and motion,
        D = 6).
    seen : array of bool, shape (n, P)
        The parts seen in each frame; a frame with none seen carries no evidence.
    carry : array, shape (n, C)
        The body's features, shared by every part (:class:`Motion`'s travel and turn, C = 5; C = 0 for
        :class:`Poses`).
    carried : array of bool, shape (n,)
        Whether the carry is known (where the body goes needs its world positions).
    noise : array, shape (n, 2), or None
        The tracker's jitter in each frame's features, squared, as it adds to the squared distance of two frames
        (:mod:`plugins.lib.jitter`): the mean over the frame's parts seen of the part's squared shape noise and of its
        squared motion noise (the second scales with a performance's tempo as the motion does); the search takes it
        out of its distances (:func:`plugins.matchers.tempo.less_jitter`). ``None``: none known, 0 (the papers'
        characters, a motion authored as key poses).
    """

    parts: np.ndarray
    seen: np.ndarray
    carry: np.ndarray
    carried: np.ndarray
    noise: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.parts)

    @cached_property
    def products(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What :meth:`Motion.costs` multiplies, kept with the frames (a repertoire's are computed once): the parts
        with the unseen ones zeroed, flat (n, P * D); their squared norms (n, P); the mask as numbers (n, P); the
        carry with the unknown ones zeroed (n, C) and its squared norms (n,)."""
        seen = self.seen.astype(float)
        masked = self.parts * seen[..., None]
        carry = np.where(self.carried[:, None], self.carry, 0.0)
        return (masked.reshape(len(self), -1), np.einsum("npd,npd->np", masked, masked), seen, carry,
                np.einsum("nc,nc->n", carry, carry))

    @cached_property
    def split(self) -> Split:
        """The features by how they scale with a performance's tempo (:class:`Split`), kept with the frames (a
        repertoire's are computed once). Six features a part are its shape and its motion (:class:`Motion`), three
        its motion alone (``shape = "none"``)."""
        n = len(self)
        shape, motion, travel, turn = self._by_tempo()
        return Split(shape.reshape(n, -1), motion.reshape(n, -1), travel, turn, self.seen.astype(float),
                     np.einsum("npd,npd->np", shape, shape), np.einsum("npd,npd->np", motion, motion),
                     np.einsum("nc,nc->n", travel, travel), np.einsum("nc,nc->n", turn, turn))

    @cached_property
    def single(self) -> tuple[np.ndarray, ...]:
        """:attr:`split`'s shape, motion, travel and turn contiguous in single precision (a distance in body sizes needs
        no more than seven digits, and half the numbers to read), and each frame's mean squared motion over its parts
        (kept with the frames: a repertoire's are made once): what :func:`_split_full` reads."""
        n, parts = self.seen.shape
        shape, motion, travel, turn = self._by_tempo()
        shape, motion = shape.reshape(n, -1), motion.reshape(n, -1)
        return (*(np.ascontiguousarray(v, dtype=np.float32) for v in (shape, motion, travel, turn)),
                np.einsum("nk,nk->n", motion, motion) / max(parts, 1))

    def _by_tempo(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The parts' shape (n, P, 3; none without it) and motion (n, P, 3), the unseen ones zeroed, and the body's
        travel (n, 3) and turn (n, 2), the unknown ones zeroed: the features by how they scale with tempo."""
        dims = self.parts.shape[2]
        masked = self.parts if self.seen.all() else self.parts * self.seen[..., None]
        carry = self.carry if self.carried.all() else np.where(self.carried[:, None], self.carry, 0.0)
        return (masked[..., :3] if dims == 6 else masked[..., :0]), masked[..., dims - 3 :], carry[:, :3], carry[:, 3:]

    @property
    def floor(self) -> np.ndarray:
        """:attr:`noise`, zeros where none is known, (n, 2)."""
        return self.noise if self.noise is not None else np.zeros((len(self), 2))

    def take(self, rows: np.ndarray | slice) -> Frames:
        """The frames ``rows`` of this sequence."""
        return Frames(self.parts[rows], self.seen[rows], self.carry[rows], self.carried[rows],
                      None if self.noise is None else self.noise[rows])

    @staticmethod
    def join(sequences: list[Frames]) -> Frames:
        """Sequences one after another (each keeps the features it was given: a take's shape about its own mean)."""
        noise = None if all(s.noise is None for s in sequences) else np.concatenate([s.floor for s in sequences])
        return Frames(*(np.concatenate([getattr(s, f) for s in sequences]) for f in
                        ("parts", "seen", "carry", "carried")), noise)


class Split(NamedTuple):
    """A sequence's features by how they scale with its tempo (:attr:`Frames.split`), unseen parts and unknown
    carries zeroed: the parts' shape (n, P * 3; none without it) and motion (n, P * 3), the body's travel (n, 3) and
    turn (n, 2), the mask as numbers (n, P), and the squared norms of each: per part (n, P) for shape and motion, per
    frame (n,) for travel and turn."""

    shape: np.ndarray
    motion: np.ndarray
    travel: np.ndarray
    turn: np.ndarray
    seen: np.ndarray
    shape2: np.ndarray
    motion2: np.ndarray
    travel2: np.ndarray
    turn2: np.ndarray


class Paired:
    """Every frame of ``a`` against every frame of ``b``, ready to be costed with ``a`` played at other speeds
    (:meth:`at`): the mean squares of :meth:`Motion.costs` split by how they scale, ``|s x - y|^2 = s^2 |x|^2 +
    |y|^2 - 2 s x.y``, so that the squared cost at speed ``s`` is ``fixed + s * moving + s^2 * moving2`` (arrays
    (len(a), len(b)); ``moving2`` may be (len(a), 1) where it does not depend on ``b``'s frame), computed once.

    :meth:`between` computes them as matrix products (every pair at once); :meth:`pairwise` row by row, each row's
    numbers the same whatever rows come with it (a matrix product's rounding depends on how many rows it
    multiplies): for a forward model fed rows one by one or at once."""

    def __init__(self, fixed: np.ndarray, moving: np.ndarray, moving2: np.ndarray) -> None:
        self.fixed, self.moving, self.moving2 = fixed, moving, moving2

    @classmethod
    def between(cls, a: Frames, b: Frames) -> Paired:
        """As matrix products over the parts seen in both (sums over the frames' parts where every part is seen
        in both)."""
        x, y = a.split, b.split
        fixed = x.shape @ y.shape.T
        moving = x.motion @ y.motion.T
        if a.seen.all() and b.seen.all():  # every part in both: the sums over the parts are each frame's own
            parts = max(a.seen.shape[1], 1)
            fixed *= -2.0 / parts
            fixed += (x.shape2.sum(axis=1) / parts)[:, None]
            fixed += ((y.shape2.sum(axis=1) + y.motion2.sum(axis=1)) / parts)[None, :]
            moving *= -2.0 / parts
            moving2 = (x.motion2.sum(axis=1) / parts)[:, None]
            carried = None
        else:
            count = x.seen @ y.seen.T
            inverse = np.divide(1.0, count, out=np.zeros_like(count), where=count > 0)
            fixed = (x.shape2 @ y.seen.T + x.seen @ (y.shape2 + y.motion2).T - 2.0 * fixed) * inverse
            moving2 = (x.motion2 @ y.seen.T) * inverse
            moving *= -2.0 * inverse
            carried = count > 0
        if a.carry.shape[1] and a.carried.any() and b.carried.any():  # per frame pair, added to every part's
            both = np.outer(a.carried, b.carried)  # square: once to the mean over the parts
            carried = both if carried is None else both & carried
            turn = x.turn @ y.turn.T
            turn *= -2.0
            turn += x.turn2[:, None]
            turn += (y.turn2 + y.travel2)[None, :]
            travel = x.travel @ y.travel.T
            travel *= -2.0
            if carried.all():
                fixed += turn
                moving += travel
                moving2 = moving2 + x.travel2[:, None]
            else:
                fixed += np.where(carried, turn, 0.0)
                moving += np.where(carried, travel, 0.0)
                moving2 = moving2 + np.where(carried, x.travel2[:, None], 0.0)
        return cls(fixed, moving, moving2)

    @classmethod
    def pairwise(cls, a: Frames, b: Frames) -> Paired:
        """:meth:`between` row by row, each row's numbers the same whatever rows come with it: a row with every part
        seen, against frames with every part seen, in a compiled loop (:func:`_split_full`); any other row on its own
        by :meth:`between`."""
        n, m = len(a), len(b)
        fixed, moving, moving2 = np.empty((n, m)), np.empty((n, m)), np.empty((n, m))
        whole = a.seen.all(axis=1) & bool(b.seen.all()) if m else np.zeros(n, dtype=bool)
        if whole.all() and n:
            kernel(_split_full, reordered=True)(*a.single[:4], a.carried, *b.single, b.carried,
                                                1.0 / max(b.seen.shape[1], 1), fixed, moving, moving2)
            return cls(fixed, moving, moving2)
        if whole.any():
            rows = np.flatnonzero(whole)
            out = [np.empty((len(rows), m)) for _ in range(3)]
            kernel(_split_full, reordered=True)(*a.take(whole).single[:4], a.carried[whole], *b.single, b.carried,
                                                1.0 / max(b.seen.shape[1], 1), *out)
            fixed[rows], moving[rows], moving2[rows] = out
        for i in np.flatnonzero(~whole):
            one = cls.between(a.take([i]), b)
            fixed[i], moving[i], moving2[i] = one.fixed[0], one.moving[0], one.moving2[0]
        return cls(fixed, moving, moving2)

    def at(self, speed: np.ndarray | float = 1.0) -> np.ndarray:
        """The costs (len(a), len(b)) with ``a``'s motion and travel multiplied by ``speed`` (a number, or one for each
        frame of ``b``): :meth:`Motion.costs` of ``a`` played ``speed`` times as fast (shape and turn do not change
        with tempo)."""
        s = np.asarray(speed, dtype=float)
        square = self.moving * s
        square += self.fixed
        square += self.moving2 * (s * s)
        np.maximum(square, 0.0, out=square)
        return np.sqrt(square, out=square)


def _split_full(a_shape, a_motion, a_travel, a_turn, a_carried, b_shape, b_motion, b_travel, b_turn, b_motion2,
                b_carried, inverse, fixed, moving, moving2):
    """:class:`Paired` of every pair of frames with every part seen in both, pair by pair: the features a frame after
    another in single precision (:attr:`Frames.single`: shape and motion (n, P * 3) each, travel, turn),
    ``b_motion2`` each frame of ``b``'s mean squared motion over its parts and ``inverse`` one over the number of
    parts; the sums over a frame's features in single precision, the rest in double. Plain Python, compiled by
    :func:`~plugins.lib.compiled.kernel` (reordered sums: the same order at every call, so a row's numbers do not
    depend on the rows beside it)."""
    n = a_motion.shape[0]
    m = b_motion.shape[0]
    width_shape = a_shape.shape[1]
    width = a_motion.shape[1]
    for i in range(n):
        shape_a = a_shape[i]
        motion_a = a_motion[i]
        square = np.float32(0.0)
        for k in range(width):
            square += motion_a[k] * motion_a[k]
        travel2 = np.float64(0.0)
        for k in range(3):
            travel2 += np.float64(a_travel[i, k]) * a_travel[i, k]
        for j in range(m):
            shape_b = b_shape[j]
            motion_b = b_motion[j]
            fs = np.float32(0.0)
            for k in range(width_shape):
                d = shape_a[k] - shape_b[k]
                fs += d * d
            xs = np.float32(0.0)
            for k in range(width):
                xs += motion_a[k] * motion_b[k]
            f = np.float64(fs) * inverse + b_motion2[j]
            x = np.float64(xs) * inverse
            q = np.float64(square) * inverse
            if a_carried[i] and b_carried[j]:
                for k in range(3):
                    f += np.float64(b_travel[j, k]) * b_travel[j, k]
                    x += np.float64(a_travel[i, k]) * b_travel[j, k]
                for k in range(2):
                    d2 = np.float64(a_turn[i, k]) - b_turn[j, k]
                    f += d2 * d2
                q += travel2
            fixed[i, j] = f
            moving[i, j] = -2.0 * x
            moving2[i, j] = q


class Fixed:
    """Costs that do not change with tempo (positions, eq. 1): :meth:`at` gives them whatever the speed."""

    def __init__(self, costs: np.ndarray) -> None:
        self.costs = costs

    def at(self, speed: np.ndarray | float = 1.0) -> np.ndarray:
        return self.costs


class Comparison(ABC):
    """How frames are compared: :meth:`frames` of a sequence, :meth:`costs` between two."""

    name: ClassVar[str]
    unit: ClassVar[str]
    """What a distance is measured in ("m": metres; "body": the demonstrator's body sizes)."""

    @abstractmethod
    def frames(self, poses: np.ndarray, visible: np.ndarray, fps: float, *, velocity: np.ndarray | None = None,
               travel: np.ndarray | None = None, heading: np.ndarray | None = None,
               size: float | None = None, noise: np.ndarray | None = None) -> Frames:
        """The frames of a sequence of root-relative poses.

        Parameters
        ----------
        poses : array, shape (n, P, 3)
            Root-relative poses in the body's frame (hidden parts held where last seen, NaN if never seen).
        visible : array of bool, shape (n, P)
        fps : float
            Frames per second of the sequence.
        velocity : array, shape (n, P, 3), optional
            Each part's velocity relative to the root (m/s), where it is known better than from ``poses`` (a
            posegraph's nodes keep their clip's, measured at the clip's frame rate); ``None``: derived here.
        travel : array, shape (n, 3), optional
            The root's velocity in the body's own frame (m/s); ``None`` or NaN rows: not known.
        heading : array, shape (n,), optional
            The body's heading (radians, about +y) relative to the sequence's first frame; ``None`` or NaN: not known.
        size : float, optional
            The body size the lengths are measured in (:func:`plugins.lib.body_size.body_scale`); ``None``: from
            the sequence's own median pose.
        noise : array, shape (P, 2), (n, P, 2) or (n, 1, 2), optional
            Each part's squared jitter in its position (m^2) and its velocity ((m/s)^2), three axes together
            (:func:`plugins.lib.jitter.feature_noise`; one for every part: their mean), which a comparison that sees
            it keeps as :attr:`Frames.noise`; ``None``: none known.
        """

    paced: ClassVar[bool] = False
    """Whether the frames carry velocities, which scale with a performance's tempo (:meth:`paired`)."""

    def paired(self, a: Frames, b: Frames) -> Paired | Fixed:
        """Every frame of ``a`` against every frame of ``b``, to be costed with ``a`` at other speeds (``.at(speed)``,
        :mod:`plugins.matchers.tempo`). Positions have no tempo: :meth:`costs` whatever the speed."""
        return Fixed(self.costs(a, b))

    def costs(self, a: Frames, b: Frames) -> np.ndarray:
        """Every frame of ``a`` against every frame of ``b``: eq. 1 over the parts seen in both, (len(a), len(b)).
        A pair with no part seen in both costs 0 (no evidence either way). Compiled (:func:`_eq1`)."""
        out = np.empty((len(a), len(b)))
        if out.size:
            kernel(_eq1)(np.ascontiguousarray(a.parts, dtype=np.float64), a.seen, np.ascontiguousarray(a.carry,
                      dtype=np.float64), a.carried, np.ascontiguousarray(b.parts, dtype=np.float64), b.seen,
                      np.ascontiguousarray(b.carry, dtype=np.float64), b.carried, out)
        return out

    @abstractmethod
    def still(self, frames: Frames) -> np.ndarray:
        """Each frame's distance to standing still: how much there is to explain, (n,). The share of a
        demonstration that a movement leaves unexplained is its distance over this one
        (:mod:`plugins.matchers.decision`)."""


def _eq1(a, a_seen, a_carry, a_carried, b, b_seen, b_carry, b_carried, out):
    """eq. 1 of every frame pair: ``out[i, j]`` the mean over the parts seen in both of the Euclidean norm of the
    part's difference, the carries' difference (where both are known) added to each part's squared norm; 0 where
    no part is seen in both. Plain Python as written (the reference), compiled by
    :func:`~plugins.lib.compiled.kernel`."""
    n, parts, dims = a.shape
    m = b.shape[0]
    width = a_carry.shape[1]
    for i in range(n):
        for j in range(m):
            carry = 0.0
            if width and a_carried[i] and b_carried[j]:
                for c in range(width):
                    d = a_carry[i, c] - b_carry[j, c]
                    carry += d * d
            total = 0.0
            count = 0
            for p in range(parts):
                if a_seen[i, p] and b_seen[j, p]:
                    sq = carry
                    for k in range(dims):
                        d = a[i, p, k] - b[j, p, k]
                        sq += d * d
                    total += np.sqrt(sq)
                    count += 1
            out[i, j] = total / count if count else 0.0


class Poses(Comparison):
    """Buchsbaum & Blumberg 2005, eq. 1-2: root-relative positions, in metres (the papers)."""

    name = "poses"
    unit = "m"

    def frames(self, poses, visible, fps, *, velocity=None, travel=None, heading=None, size=None,
               noise=None) -> Frames:
        """:meth:`Comparison.frames`: eq. 1 as the paper has it, the jitter in it (``noise`` is not used)."""
        poses = np.asarray(poses, dtype=float)
        seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
        n = len(poses)
        return Frames(np.where(seen[..., None], poses, 0.0), seen, np.zeros((n, 0)), np.zeros(n, dtype=bool))

    def still(self, frames: Frames) -> np.ndarray:
        """Each frame's eq. 1 distance to the sequence's mean pose (its own posture held still), (n,)."""
        counts = frames.seen.sum(axis=0)
        mean = (frames.parts * frames.seen[..., None]).sum(axis=0) / np.maximum(counts, 1)[:, None]
        d = np.sqrt(((frames.parts - mean) ** 2).sum(axis=-1))
        count = frames.seen.sum(axis=1)
        return np.where(count > 0, (d * frames.seen).sum(axis=1) / np.maximum(count, 1), 0.0)


class Motion(Comparison):
    """Shape, motion and carry of every part, in body sizes (see the module).

    ``shape = False``: motion and carry only, what can be compared before a movement is over (the shape needs the
    whole movement's mean posture): the forward model's, which predicts while the demonstration comes in."""

    name = "motion"
    unit = "body"

    def __init__(self, shape: str = "mean") -> None:
        if shape not in ("mean", "onset", "none"):
            raise ValueError(f"shape must be 'mean', 'onset' or 'none', not {shape!r}")
        self.shape = shape

    def frames(self, poses, visible, fps, *, velocity=None, travel=None, heading=None, size=None, noise=None,
               origin=None) -> Frames:
        """:meth:`Comparison.frames`; ``origin`` (P, 3): with ``shape = "onset"``, the pose the shape is measured
        from (default: the first frame's). ``noise``: kept in body sizes as :attr:`Frames.noise`, each frame's mean
        over its parts seen (the shape's about the mean pose as the position's; the motion's times
        :data:`HORIZON` squared)."""
        poses = np.asarray(poses, dtype=float)
        seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
        n = len(poses)
        filled = np.where(seen[..., None], poses, 0.0)
        if size is None:
            size = sequence_size(filled, seen)
        scale = 1.0 / size if size > 0 else 0.0
        if self.shape == "onset":
            shape = (filled - (filled[:1] if origin is None else np.asarray(origin, dtype=float))) * scale
        else:
            counts = seen.sum(axis=0)
            mean = (filled * seen[..., None]).sum(axis=0) / np.maximum(counts, 1)[:, None]
            shape = (filled - mean) * scale
        if velocity is None:
            velocity = derivative(filled, fps)
        motion = np.nan_to_num(np.asarray(velocity, dtype=float)) * (HORIZON * scale)
        carry = np.zeros((n, 5))
        carried = np.zeros(n, dtype=bool)
        if travel is not None and heading is not None:
            travel = np.asarray(travel, dtype=float)
            heading = np.asarray(heading, dtype=float)
            carried = np.isfinite(travel).all(axis=1) & np.isfinite(heading)
            carry[:, :3] = np.where(carried[:, None], travel, 0.0) * (HORIZON * scale)
            turn = np.where(carried, heading, 0.0)
            carry[:, 3] = np.cos(turn) - 1.0
            carry[:, 4] = np.sin(turn)
        floor = None
        if noise is not None:
            per_part = np.broadcast_to(np.asarray(noise, dtype=float), (n, seen.shape[1], 2)) * seen[..., None]
            floor = per_part.sum(axis=1) / np.maximum(seen.sum(axis=1), 1)[:, None] * \
                np.array([0.0 if self.shape == "none" else scale * scale, (HORIZON * scale) ** 2])
        return Frames(motion if self.shape == "none" else np.concatenate([shape, motion], axis=2), seen, carry,
                      carried, floor)


    paced = True

    def paired(self, a: Frames, b: Frames) -> Paired:
        return Paired.between(a, b)

    def still_at(self, frames: Frames, speeds: np.ndarray) -> np.ndarray:
        """:meth:`still` of the frames played ``speeds`` (K,) times as fast (their motion and travel multiplied by
        it), (n, K)."""
        s = np.asarray(speeds, dtype=float)[None, :]
        fixed, moving2 = self.still_split(frames)
        return np.sqrt(fixed[:, None] + s * s * moving2[:, None])

    def still_split(self, frames: Frames) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`still` split by how it scales with tempo: each frame's distance to standing still played ``s``
        times as fast is ``sqrt(fixed + s^2 * moving2)`` (the shape and the turn; the motion and the travel), (n,)
        each; both 0 in a frame with no part seen."""
        n, parts, dims = frames.parts.shape
        if frames.seen.all():  # the sums over every part at once (a block of a forward model's samples)
            square = np.einsum("npd,npd->nd", frames.parts, frames.parts) / max(parts, 1)
            carry = frames.carry * frames.carried[:, None] if frames.carry.shape[1] else np.zeros((n, 5))
            carry *= carry
            return (square[:, : dims - 3].sum(axis=1) + carry[:, 3:].sum(axis=1),
                    square[:, dims - 3 :].sum(axis=1) + carry[:, :3].sum(axis=1))
        x = frames.split
        count = x.seen.sum(axis=1)
        some = count > 0
        inverse = np.where(some, 1.0 / np.maximum(count, 1), 0.0)
        fixed = x.shape2.sum(axis=1) * inverse + np.where(some, x.turn2, 0.0)
        moving2 = x.motion2.sum(axis=1) * inverse + np.where(some, x.travel2, 0.0)
        return fixed, moving2

    def costs(self, a: Frames, b: Frames) -> np.ndarray:
        """Every frame of ``a`` against every frame of ``b``: the root mean square over the parts seen in both of
        each part's difference with the carries' (where both are known) added, (len(a), len(b)); 0 where no part
        is seen in both. As matrix products: the sum over the parts seen in both of ``|x|^2 + |y|^2 - 2 x.y``
        (:attr:`Frames.products`); best on one BLAS thread (:func:`plugins.lib.compiled.one_thread`)."""
        xa, na, sa, ca, qa = a.products
        xb, nb, sb, cb, qb = b.products
        count = sa @ sb.T
        square = na @ sb.T + sa @ nb.T - 2.0 * (xa @ xb.T)
        if ca.shape[1]:
            carry = qa[:, None] + qb[None, :] - 2.0 * (ca @ cb.T)
            square += np.where(np.outer(a.carried, b.carried), carry, 0.0) * count
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(count > 0, square / np.maximum(count, 1.0), 0.0)
        return np.sqrt(np.maximum(mean, 0.0))

    def still(self, frames: Frames) -> np.ndarray:
        """Each frame's distance to standing still, every feature zero (no excursion from the mean posture, no
        motion, no carry): the root mean square of its parts' norms with the carry's, (n,) (:meth:`still_split` at
        the frames' own tempo)."""
        fixed, moving2 = self.still_split(frames)
        return np.sqrt(fixed + moving2)

    def of_motion(self, motion, body, rows: np.ndarray, fps: float) -> Frames:
        """The frames of a whole observed motion (a segment in working memory, with its world positions) at its
        frames ``rows``, given as a sequence of ``fps`` frames a second.

        Where the world positions are known, the body's frame is found again from them over the whole segment, as
        it is for the clips a repertoire is built from (:func:`plugins.lib.clip_repertoire.root_relative_motion`:
        the facing a centred running median over :data:`FACING_WINDOW`): a perception that watches live can only
        look back, so its facing lags behind a turn, and the parts would be seen swinging sideways as the body
        turns. Each part's motion is derived at the motion's own frame rate before the rows are taken, and the
        body size is the segment's."""
        positions, visible = motion.positions, motion.visible
        travel = heading = None
        if motion.world is not None and np.isfinite(motion.world).any():
            window = max(1, int(round(FACING_WINDOW * motion.fps)))
            local, seen, _, _ = root_relative(motion.world, motion.visible, body, RecordingFacing(window))
            if seen.any():
                positions, visible = local, seen
                travel = body_velocity(motion.world, local, seen, body.root_index, motion.fps, frames=rows)
                heading = turned(motion.world, local, seen, body.root_index)[rows]
        seen = visible & np.isfinite(positions).all(axis=-1)
        relative = np.where(seen[..., None], positions, 0.0)
        root = body.root_index
        held = _held(relative, seen)
        velocity = derivative(held - held[:, root : root + 1], motion.fps)[rows]
        noise = feature_noise(jitter_about_root(relative, seen, motion.fps, body), motion.fps, motion.n_frames)
        return self.frames(held[rows], seen[rows], fps, velocity=velocity, travel=travel, heading=heading,
                           size=sequence_size(relative, seen), noise=noise)


FACING_WINDOW = 1.0
"""Seconds of the centred running median of the facing when a whole segment's frame is found again."""


def _held(positions: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """Each part held where it was last seen (first seen, before that), docs/conventions.md; 0 if never seen."""
    out = positions.copy()
    for p in np.flatnonzero(~seen.all(axis=0)):
        rows = np.flatnonzero(seen[:, p])
        if not len(rows):
            out[:, p] = 0.0
            continue
        last = np.maximum.accumulate(np.where(seen[:, p], np.arange(len(seen)), -1))
        out[:, p] = positions[np.where(last >= 0, last, rows[0]), p]
    return out


def sequence_size(poses: np.ndarray, seen: np.ndarray) -> float:
    """A sequence's body size: :func:`plugins.lib.body_size.body_scale` of each part's median position over the
    frames it is seen (0 when fewer than two parts are ever seen). Every part seen in every frame (a forward model's
    onset, mostly): the plain median, which is what ``nanmedian`` computes when nothing is masked, without its
    masking."""
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a part never seen: its median is NaN, and left out
        if len(poses) and seen.all() and np.isfinite(poses).all():
            median = np.median(poses, axis=0)
        else:
            median = np.nanmedian(np.where(seen[..., None], poses, np.nan), axis=0)
    return float(body_scale(median))


COMPARISONS: dict[str, type[Comparison]] = {"poses": Poses, "motion": Motion}
"""The comparisons by the name a matcher's ``comparison`` parameter takes."""


def comparison(name: str) -> Comparison:
    """The comparison called ``name`` (:data:`COMPARISONS`)."""
    return COMPARISONS[name]()
