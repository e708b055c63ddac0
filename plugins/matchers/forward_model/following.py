"""The forward model following real people: every command predicts the demonstration, compared by its motion.

Kopp & Graeser 2006, §4.4: when a demonstration begins, the commands one knows predict it in parallel, each by its
forward model; a candidate whose prediction parts from what is seen drops out, and when one movement prevails it is
imitated at once, before the demonstration is over (*response facilitation*). The paper's own mechanism follows the
wrist's guiding strokes of a body like one's own and drops a candidate beyond a fixed error in metres
(:mod:`plugins.matchers.forward_model.tracks`). Another person's body, stance, style and tempo put every such
prediction off from the first frame. Here the same parallel prediction and drop-out work with the comparison and
the decision the matchers share:

- **prediction**: each take one has learned (a chain of commands, :meth:`MotorCommandGraph.takes`) is played by its
  commands' forward models (the guiding strokes' positions over the command's time) at :data:`RATE` samples a
  second, with where the body went and how far it turned while the command was shown (:attr:`Edge.travel`,
  :attr:`Edge.turn`);
- **comparison**: what a forward model can compare before a movement is over (:class:`plugins.matchers.comparison.
  Motion` with its shape taken from the onset, K&G's prediction from the active node, rather than about the whole
  movement's mean posture, which is not known yet): where each part has gone since the movement began, how it
  moves, how the body carries it, in the demonstrator's own body sizes; the demonstration's frames are taken as they
  arrive, the body's facing from a running median over the last :data:`FACING` seconds (the forward marker's side
  put to the same window's vote, :class:`plugins.lib.root_frame.HeadingFilter`);
- **tempo**: each prediction is followed at whatever pace the demonstration goes, by time warping advanced sample by
  sample, each take at the pace its own best path has gone so far (:class:`plugins.matchers.pacing.PacedWarping`):
  K&G re-parameterise a command by the path length seen (§4.4); here the warping finds for every sample the point
  of each prediction that fits best so far, and the demonstration's motion is compared at the take's tempo (a walk
  at half the pace is compared with the take's walk as if it went at the take's pace);
- **drop-out and commitment**: each movement's score is its best take's distance so far over the demonstration's
  own distance to standing still (at that take's pace), held to the calibrated threshold
  (:class:`plugins.matchers.decision.Calibrated`, calibrated on the predictions themselves followed the same way,
  each take left out of its movement and each movement left out). A movement *prevails* when it has been the
  nearest within the threshold at every sample of the last :data:`RECENT` seconds; it is committed to once it
  prevails and ``min_progress`` of its take has been followed (``Match.decided_at``: response facilitation). When
  another movement prevails over a committed one, the demonstration has deviated from it (``stop``, Fig. 3's
  "stop imitation") and the other is committed to (Fig. 3: back to the last correct node, predict again, and
  imitate what prevails);
- **the answer at the end**: every movement's score over the whole demonstration, decided as path search decides
  (:mod:`plugins.matchers.decision`); with ``comparison = "motion+strokes"`` the takes' strokes mixed in, on a
  calibration of their own (:mod:`plugins.matchers.forward_model.answer`). A commitment stands when it is that
  answer (its ``decided_at`` is when it was committed to); otherwise the answer at the end replaces it (K&G §4.4:
  the demonstration must end where the committed movement does);
- **standing still**: a movement whose commands predict no motion at all (a pose held) is never committed to early;
  when it comes nearest at the end, the demonstration is it if it moved at most half as much as the least moving
  other movement (:class:`plugins.matchers.decision.Stillness`), else unknown;
- **a tracker's gaps**: a sample in which no part is seen (the root lost: nothing is root-relative) carries no
  evidence and the warping does not advance on it; each part's onset, and the body's size, are taken from where the
  part was first seen;
- **learning** (``learn = true``, as ``likeme imitate`` sets it): a demonstration whose answer at the end is unknown
  becomes the take of a new movement (K&G §4.3, :class:`~plugins.matchers.forward_model.learning.TakeLearning`),
  predicted from the next demonstration on.

The candidates are the takes a motor command graph learned from labelled clips (:meth:`MotorCommandGraph.takes`):
this is the forward model for a repertoire of recordings; a character who learns by watching follows the paper's
guiding strokes (``comparison = "strokes"``).
"""

from __future__ import annotations

from functools import lru_cache, partial
from typing import Any, Protocol

import numpy as np

from plugins.lib.compiled import one_thread
from plugins.lib.root_frame import HeadingFilter, facing_heading, to_root_relative
from plugins.lib.velocity import derivative, window_frames
from plugins.matchers.comparison import Frames, Motion, sequence_size
from plugins.matchers.decision import Calibrated, Calibration, Decision, Stillness, relative_scores
from plugins.matchers.forward_model.answer import Answer, FollowedScores
from plugins.matchers.pacing import PacedWarping, followed_scores
from plugins.matchers.strokes_evidence import PLAYED_FPS
from plugins.matchers.warping import Chains, chain_rows, chain_stills
from toolkit import Match
from toolkit import Motion as Recording

__all__ = ["FACING", "Following", "RATE", "RECENT", "Streaming"]

RATE = 10.0
"""Samples a second at which predictions and demonstrations are compared: the posegraph's node rate (B&B §4.1),
fine enough for human movements (the velocities are smoothed over :data:`plugins.lib.velocity.SMOOTHING` first)."""

FACING = 0.5
"""Seconds of the running median of the facing while a demonstration comes in (looking back only)."""

PLAY_FPS = 30.0
"""Frames a second at which a command's prediction is played before its velocities are taken and it is sampled."""

TRAVEL = 0.25
"""Seconds over which the root's velocity is averaged (:func:`plugins.lib.travel.body_velocity`'s window)."""

BLOCK = 0.3
"""Seconds of frames the watching loop's rows are taken in at once, live (three samples): the frame each answer is
decided at stays the sample's; it is reported up to this much later, for a tenth of the work per frame."""

RECENT = 0.5
"""Seconds over which a movement must have been the nearest within the threshold, sample after sample, to prevail
(to be committed to, or to replace a commitment): a lead that lasts, not a sample's noise."""

class Takes(Protocol):
    """What following real people needs of a motor system: a motor command graph that learned takes from clips."""

    body: Any
    subsystems: dict[str, Any]

    def takes(self) -> dict[str, list[tuple[tuple[str, ...], str, Any, float]]]:
        """Movement -> one ``(edges, subsystem, observed, fps)`` per clip it was learned from."""

    def edge(self, movement: str) -> Any:
        """The edge record of a movement (edge) name: its commands, travel and turn."""

    def play_take(self, edges: tuple[str, ...], subsystem: str, fps: float = 30.0) -> list[np.ndarray]:
        """A take's edges played by their commands, the other parts at rest: frames (n, P, 3) per edge."""

    def take_motions(self, fps: float = 30.0) -> dict[str, list[Any]]:
        """Movement -> each take (in the order of ``takes()``) as a motion (``None``: one with no frame)."""


class Prediction:
    """Every take's predicted frames, chain after chain (:class:`plugins.matchers.warping.Chains`)."""

    def __init__(self, motor: Any, comparison: Motion) -> None:
        root = motor.body.root_index
        takes, movements, lengths, sources = [], [], [], []
        for movement, chains in motor.takes().items():
            for k, (edges, subsystem, _, _) in enumerate(chains):
                frames = self._take(motor, edges, subsystem, root, comparison)
                if frames is not None and len(frames):
                    takes.append(frames)
                    movements.append(movement)
                    lengths.append(len(frames))
                    sources.append((movement, k))
        self.takes = takes
        self.chains = Chains.of_lengths(lengths, movements)
        self.frames = Frames.join(takes) if takes else None
        self.sources = sources  # each chain's movement and the take's place among the movement's takes

    def motions(self, motor: Any) -> list[Recording | None]:
        """Each chain's take as a motion (:meth:`MotorCommandGraph.take_motions`), in the chains' order."""
        played = motor.take_motions(fps=PLAYED_FPS)
        return [played[movement][k] for movement, k in self.sources]

    @staticmethod
    def _take(motor, edges, subsystem, root, comparison) -> Frames | None:
        """One take's commands played (:meth:`MotorCommandGraph.play_take`: the parts' positions predicted by their
        commands, the others held at rest), their velocities, the travel and the turn shown with each command,
        sampled at :data:`RATE`."""
        idx = motor.subsystems[subsystem]
        pieces = motor.play_take(edges, subsystem, PLAY_FPS)
        travel, turn, shown, turned = [], [], [], 0.0
        for name, frames in zip(edges, pieces):
            edge = motor.edge(name)
            at = np.linspace(0.0, 1.0, len(frames))
            travel.append(_along(edge.travel, at, 3))
            turn.append(turned + _along(edge.turn, at, 1)[:, 0])
            turned = turn[-1][-1]
            if edge.shown is not None:
                shown.append(edge.shown)
        if not pieces:
            return None
        played = np.concatenate(pieces)
        relative = played - played[:, root : root + 1]
        velocity = derivative(relative, PLAY_FPS)
        keep = np.round(np.arange(0.0, len(played) / PLAY_FPS, 1.0 / RATE) * PLAY_FPS).astype(int)
        keep = keep[keep < len(played)]
        size = _size(np.concatenate(shown) if shown else relative[:, idx])
        return comparison.frames(relative[keep], np.ones((len(keep), relative.shape[1]), dtype=bool), RATE,
                                 velocity=velocity[keep], travel=np.concatenate(travel)[keep],
                                 heading=np.concatenate(turn)[keep], size=size)


def _along(values: np.ndarray | None, at: np.ndarray, width: int) -> np.ndarray:
    """``values`` (m, width) or (m,) read at the shares ``at`` (0..1) of their length; NaN rows where not known."""
    if values is None or len(values) == 0:
        return np.full((len(at), width), np.nan)
    values = np.asarray(values, dtype=float).reshape(len(values), -1)
    where = at * (len(values) - 1)
    return np.stack([np.interp(where, np.arange(len(values)), values[:, k]) for k in range(values.shape[1])], axis=1)


def _size(poses: np.ndarray) -> float:
    """The body size of poses (n, k, 3): :func:`plugins.lib.body_size.body_scale` of their median."""
    from plugins.lib.body_size import body_scale

    return float(body_scale(np.median(poses, axis=0)))


@lru_cache(maxsize=16)
def _window_fits(taps: int, fps: float) -> np.ndarray:
    """The Savitzky-Golay derivative of :func:`plugins.lib.velocity.derivative` (second order, ``taps`` frames) at
    each position of its window, as weights of the window's frames (taps, taps): row ``k`` the parabola through the
    window differentiated at its ``k``-th frame, row ``taps // 2`` the centred filter, the others the window's own fit
    near an end (scipy's ``mode = "interp"``). Made once for a frame rate, not at every segment."""
    from scipy.signal import savgol_coeffs

    fits = np.stack([savgol_coeffs(taps, 2, deriv=1, delta=1.0 / fps, pos=k, use="dot") for k in range(taps)])
    fits.setflags(write=False)
    return fits


class Watched:
    """A demonstration as it comes in: its frames at :data:`RATE` once everything they need has been seen.

    The body's frame from the world positions with the facing a running median over the last :data:`FACING`
    seconds (as a perception watching live finds it, but over a shorter window: what the frame lags behind a turn,
    the turn's prediction would miss); each part held where it was last seen (docs/conventions.md); each sample's
    velocity a Savitzky-Golay derivative centred on it (:data:`plugins.lib.velocity.SMOOTHING`), the root's
    velocity averaged over :data:`TRAVEL` seconds centred on it, so a sample is given :attr:`delay` frames after
    its own. The body size is that of the median pose of the frames the first sample needs (the onset's).
    """

    def __init__(self, body: Any, fps: float, comparison: Motion) -> None:
        self.body, self.fps, self.comparison = body, float(fps), comparison
        self.root = body.root_index
        self.filter = HeadingFilter(max(1, int(round(FACING * fps))))
        taps = window_frames(fps)
        self.half = taps // 2
        self.fits = _window_fits(taps, self.fps)
        self.coeffs = self.fits[self.half]
        self.reach = max(1, int(round(TRAVEL * fps / 2)))
        self.delay = max(self.half, self.reach)
        parts = len(body.parts)
        self.n = 0
        self.relative = np.zeros((64, parts, 3))  # root-relative in the body's frame, each part held
        self.seen = np.zeros((64, parts), dtype=bool)
        self.roots = np.zeros((64, 3))
        self.headings = np.zeros(64)
        self.last = np.full((parts, 3), np.nan)  # where each part was last seen
        self.origin = np.zeros((parts, 3))  # where each part was first seen (root-relative): its onset
        self.found = np.zeros(parts, dtype=bool)
        self.size = 0.0
        self.first = max(self.delay, taps - 1)  # the frame the first sample can be given at (:meth:`due`)
        self.sampled = 0  # samples given so far

    def __len__(self) -> int:
        return self.n

    def _grow(self, more: int) -> None:
        need = self.n + more
        if need <= len(self.roots):
            return
        size = max(need, 2 * len(self.roots))
        for name in ("relative", "seen", "roots", "headings"):
            old = getattr(self, name)
            new = np.zeros((size, *old.shape[1:]), dtype=old.dtype)
            new[: self.n] = old[: self.n]
            setattr(self, name, new)

    def add(self, world: np.ndarray, visible: np.ndarray) -> None:
        """The next frames (k, P, 3) of world positions and their visibility."""
        world = np.asarray(world, dtype=float)
        visible = np.asarray(visible, dtype=bool) & np.isfinite(world).all(axis=-1)
        k = len(world)
        if not k:
            return
        found = facing_heading(np.where(visible[..., None], world, 0.0), visible, self.body, self.filter)
        local, seen, root, heading = to_root_relative(world, visible, self.body, self.filter.update_many(found))
        if seen.all():  # each part held where it was last seen (not seen yet: 0, and not compared)
            held = local
        else:  # the frame each part was last seen in by each frame of the block (-1: before it, self.last)
            at = np.maximum.accumulate(np.where(seen, np.arange(k)[:, None], -1), axis=0)
            held = np.where((at >= 0)[..., None], local[np.maximum(at, 0), np.arange(local.shape[1])], self.last)
        self.last = held[-1]
        held = np.nan_to_num(held)
        self._grow(k)
        rows = slice(self.n, self.n + k)
        self.relative[rows] = held - held[:, self.root : self.root + 1]
        new = seen.any(axis=0) & ~self.found
        if new.any():  # a part's onset is where it was first seen, not frame 0's 0 when it was hidden there
            first = np.argmax(seen, axis=0)
            self.origin[new] = self.relative[self.n + first[new], np.flatnonzero(new)]
            self.found |= new
        self.seen[rows] = seen
        self.roots[rows] = root
        previous = self.headings[self.n - 1] if self.n else None
        unwrapped = np.unwrap(np.concatenate([[previous], heading])) [1:] if previous is not None else np.unwrap(heading)
        self.headings[rows] = unwrapped
        self.n += k
        if self.size <= 0:
            self._measure()

    def _measure(self) -> None:
        """The body size, once the frames it is measured on are all there, however they come: the frames the first
        sample needs (:attr:`delay` + 1), from the first frame with two parts seen (the root lost at the onset:
        nothing is root-relative before it is found)."""
        two = np.flatnonzero(self.seen[: self.n].sum(axis=1) >= 2)
        if not len(two) or self.n <= two[0] + self.delay:
            return
        onset = slice(two[0], two[0] + self.delay + 1)
        self.size = sequence_size(self.relative[onset], self.seen[onset])
        self.first = max(self.first, two[0] + self.delay)

    def motion(self) -> Recording:
        """The demonstration so far as a motion: root-relative in the body's frame, each part held where it was last
        seen (0 before it was first seen, where it is not visible), at its own frame rate."""
        return Recording(self.relative[: self.n].copy(), self.fps, self.body.parts, visible=self.seen[: self.n].copy())

    def due(self, ended: bool) -> np.ndarray:
        """The frames of the samples not given yet whose frames are all there (``ended``: every sample left).

        Not before :attr:`first`: the first window of velocities and the body size are then there, and a sample is
        the same whatever blocks its frames came in (a bounded working memory gives them in small ones)."""
        if not ended and (self.size <= 0 or self.n <= self.first):
            return np.zeros(0, dtype=np.intp)
        last = self.n - 1 if ended else self.n - 1 - self.delay
        step = self.fps / RATE
        count = int(np.floor(last / step + 0.5 + 1e-9)) + 1 if last >= 0 else 0
        rows = np.round(np.arange(self.sampled, max(count, self.sampled)) * step).astype(np.intp)
        return rows[rows <= last]

    def frames(self, rows: np.ndarray) -> Frames:
        """The frames of the samples at ``rows`` (frames of the demonstration), given in order."""
        n, rows = self.n, np.asarray(rows, dtype=np.intp)
        relative, headings, roots = self.relative[:n], self.headings[:n], self.roots[:n]
        if self.size <= 0:  # a segment that ended before its size was known: what there is of it
            self.size = sequence_size(relative, self.seen[:n])
        taps = len(self.coeffs)
        if n >= taps:
            starts = np.clip(rows - self.half, 0, n - taps)
            windows = relative[starts[:, None] + np.arange(taps)]  # (r, taps, P, 3)
            velocity = np.einsum("t,rtpd->rpd", self.coeffs, windows)
            early, late = rows - self.half < 0, rows - self.half > n - taps
            if early.any():  # near an end: the window's own fit at the row (the first or last window's frames)
                velocity[early] = np.einsum("rt,tpd->rpd", self.fits[rows[early]], relative[:taps])
            if late.any():
                velocity[late] = np.einsum("rt,tpd->rpd", self.fits[rows[late] - (n - taps)], relative[n - taps : n])
        else:
            velocity = derivative(relative, self.fps)[rows]
        a = np.maximum(rows - self.reach, 0)
        b = np.minimum(rows + self.reach, n - 1)
        span = np.maximum(b - a, 1)
        v = (roots[b] - roots[a]) * (self.fps / span)[:, None]
        c, s = np.cos(headings[rows]), np.sin(headings[rows])
        travel = np.stack([c * v[:, 0] - s * v[:, 2], v[:, 1], s * v[:, 0] + c * v[:, 2]], axis=1)
        travel[b <= a] = np.nan
        turn = headings[0] - headings[rows]
        self.sampled += len(rows)
        return self.comparison.frames(relative[rows], self.seen[rows], RATE, velocity=velocity, travel=travel,
                                      heading=turn, size=self.size, origin=self.origin)


class Following:
    """K&G §4.4's parallel forward models with the shared comparison and decision (see the module).

    Parameters
    ----------
    motor : MotorCommandGraph
        Its takes (one chain of commands per clip learned from) are the candidates.
    body : Body
        The observer's body (the demonstration's parts are mapped onto it).
    decision : Decision
        Calibrated on the predictions (a :class:`Calibrated` decision) or a fixed distance.
    min_progress : float
        The share of a take that must be followed before committing to it.
    learning : TakeLearning, optional
        Learns a demonstration no take predicts as a new movement's take (K&G §4.3, true imitation), a candidate
        from the next demonstration on; ``None``: nothing is learned.
    answer : Answer, optional
        What the whole demonstration is scored by and decided on at its end
        (:mod:`plugins.matchers.forward_model.answer`); ``None``: the followed scores, by ``decision``.
    """

    def __init__(self, motor: Any, body: Any, decision: Decision, min_progress: float,
                 learning: Any | None = None, answer: Answer | None = None) -> None:
        self.motor, self.body, self.decision, self.min_progress = motor, body, decision, float(min_progress)
        self.learning = learning
        self.answer = answer if answer is not None else FollowedScores(decision)
        self.comparison = Motion(shape="onset")
        with one_thread():
            self.rebuild()

    def rebuild(self) -> None:
        """The predictions and the calibration, from the takes as they are now."""
        self._known = self._count()
        self.prediction = Prediction(self.motor, self.comparison)
        names = np.asarray(self.prediction.chains.movements, dtype=object)
        self._order = np.argsort(names, kind="stable")  # the chains grouped by movement, for reduceat
        ordered = names[self._order]
        self._heads = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]]) if len(ordered) else np.zeros(0, int)
        self.movements = [str(m) for m in ordered[self._heads]]
        self._index = {m: i for i, m in enumerate(self.movements)}
        p = self.prediction
        self._takes_moved = chain_stills(self.comparison, p.frames, p.chains.starts) if p.frames is not None \
            else np.zeros(0)  # each take's own distance to standing still (relative_scores)
        rows = self.rows()
        if isinstance(self.decision, Calibrated):
            self.decision.calibrate(Calibration.of_rows(rows, self.prediction.chains.movements))
        self.answer.rebuild(rows, self.prediction.chains.movements, partial(self.prediction.motions, self.motor))
        motion: dict[str, float] = {}
        for moved, movement in zip(self._takes_moved, self.prediction.chains.movements):
            motion[movement] = max(motion.get(movement, 0.0), float(moved))
        self.stillness = Stillness.of(motion) if self.decision.relative else Stillness()
        self.watched: Watched | None = None

    def rows(self) -> np.ndarray:
        """Each take's prediction followed as a demonstration against every other take (:func:`plugins.matchers.
        warping.chain_rows`), (C, C): the calibration's own and other scores (leave one take out, leave one movement
        out)."""
        p = self.prediction
        if p.frames is None:
            return np.zeros((0, 0))
        return chain_rows(self.comparison, p.takes, p.frames, p.chains, partial(followed_scores, rate=RATE))

    # -- following a demonstration ------------------------------------------------------------

    def _count(self) -> int:
        """How many takes the motor system knows (one learned, or loaded from a saved state, changes it)."""
        return sum(len(takes) for takes in self.motor.takes().values())

    def begin(self, fps: float) -> None:
        """A demonstration begins (with every take known by now: one learned since the last is predicted too)."""
        if self._count() != self._known:
            with one_thread():
                self.rebuild()
        self.watched = Watched(self.body, fps, self.comparison)
        self.warping = PacedWarping(self.comparison, self.prediction.frames, self.prediction.chains, RATE) \
            if self.prediction.frames is not None else None
        self._moved = 0.0  # the demonstration's summed distance to standing still (at its own tempo)
        self._samples = 0
        self.committed: str | None = None
        self.commitment: Match | None = None
        self.deviated = False
        self.ends = np.full(len(self.prediction.chains), -1, dtype=np.intp)  # after the last sample: each take's
        self.chain_scores = np.full(len(self.prediction.chains), np.inf)  # end frame and score, each movement's score
        self.scores = np.full(len(self.movements), np.inf)
        self.trace: list[tuple[int, np.ndarray]] = []  # each sample's frame and every movement's score then
        self.committed_at: int | None = None  # frames seen when committed (the last time) / when it deviated
        self.deviated_at: int | None = None
        self._leader, self._led = -1, 0
        self._prevail = max(1, int(round(RECENT * RATE)))  # samples a movement must lead to prevail

    def add(self, world: np.ndarray, visible: np.ndarray, ended: bool = False) -> list[tuple[int, Match]]:
        """The next frames of the demonstration; what the forward models decide on the samples they complete, with
        the frame (within the demonstration) each was decided at."""
        watched = self.watched
        if len(world):
            watched.add(world, visible)
        rows = watched.due(ended)
        if not len(rows) or self.warping is None:
            return []
        samples = watched.frames(rows)
        evidence = samples.seen.any(axis=1)
        if not evidence.all():  # a sample with no part seen carries no evidence: the warping does not advance on it
            rows, samples = rows[evidence], samples.take(evidence)
            if not len(rows):
                return []
        followed = self.warping.advance(samples)
        stills = followed.still  # each row on its own: the same numbers whatever the rows come in
        chain_scores = self._chain_scores(followed.distance, followed.moved)
        scores = np.minimum.reduceat(chain_scores[:, self._order], self._heads, axis=1)  # each movement's best take
        events = []
        for i, row in enumerate(rows):
            self.ends, self.chain_scores, self.scores = followed.ends[i], chain_scores[i], scores[i]
            self._moved += float(stills[i])
            self._samples += 1
            for match in self._decide(row if ended else max(row + watched.delay, watched.first)):
                events.append((row, match))
        return events

    @property
    def moving(self) -> float:
        """The demonstration's mean distance to standing still so far, at its own tempo (0 before a sample)."""
        return self._moved / self._samples if self._samples else 0.0

    def _chain_scores(self, distances: np.ndarray, moved: np.ndarray) -> np.ndarray:
        """Each take's score: its distance over the demonstration's distance to standing still at its pace, or the
        nearest take's own where it moves more (:func:`~plugins.matchers.decision.relative_scores`; its distance, for
        a decision that is not relative)."""
        if not self.decision.relative:
            return distances
        scores = relative_scores(distances, moved, self._takes_moved)
        return np.where(moved > 0, scores, np.where(distances <= 0, 0.0, np.inf))

    def _take(self, movement: int) -> int:
        """The chain of a movement's best take so far."""
        a = self._heads[movement]
        b = self._heads[movement + 1] if movement + 1 < len(self._heads) else len(self._order)
        return int(self._order[a + int(np.argmin(self.chain_scores[self._order[a:b]]))])

    def _progress(self, movement: int) -> float:
        """The share of the movement's best take its path has followed."""
        c = self._take(movement)
        return float((self.ends[c] + 1) / (self.prediction.chains.starts[c + 1] - self.prediction.chains.starts[c]))

    def _decide(self, frame: int) -> list[Match]:
        """After a sample (at ``frame``), on each movement's score then (:attr:`scores`, in :attr:`movements`
        order): a commitment, a deviation, or a deviation and the commitment that replaces it (see the module)."""
        limit, scores = self.decision.threshold(), self.scores
        self.trace.append((frame, scores))
        first = int(np.argmin(scores))
        leader = first if scores[first] <= limit and self.movements[first] not in self.stillness.still else -1
        self._led = (self._led + 1 if leader == self._leader else 1) if leader >= 0 else 0
        self._leader = leader  # a still movement is told by how little the whole demonstration moved (conclude)
        prevails = leader >= 0 and self._led >= self._prevail and self._progress(leader) >= self.min_progress
        if not prevails or self.movements[leader] == self.committed:
            return []
        order = np.argsort(scores, kind="stable")
        events = []
        if self.committed is not None:  # another prevails over it
            mine = self._index[self.committed]
            events.append(Match(self.committed, 0.0, frame, stop=True, reason="deviation", score=float(scores[mine]),
                                threshold=limit, measure=self.decision.measure))
            self.committed, self.deviated, self.deviated_at = None, True, frame + 1
        score = float(scores[leader])
        self.committed = movement = self.movements[leader]
        self.committed_at = frame + 1
        ranked = tuple((self.movements[i], float(scores[i])) for i in order)
        self.commitment = Match(movement, max(0.0, 1.0 - score / limit) if 0 < limit < np.inf else 1.0, frame,
                                candidates=ranked, score=score, threshold=limit, measure=self.decision.measure,
                                details={"progress": self._progress(leader)})
        events.append(self.commitment)
        return events

    def conclude(self, frames: int) -> Match:
        """The demonstration has ended (``frames`` long): the last samples, then the answer on all of it. The
        commitment (:attr:`commitment`, the same object) when it stands; the answer at the end when it does not (the
        commitment is then a deviation at the end: :attr:`committed` is cleared, :attr:`deviated_at` is ``frames``)."""
        self.add(np.zeros((0, len(self.body.parts), 3)), np.zeros((0, len(self.body.parts)), dtype=bool), ended=True)
        if not self._samples:
            return Match.unknown("nothing seen", details={"reason": "nothing seen"})
        self.chain_scores = self.answer.scores(self.chain_scores, self.watched.motion)
        self.scores = np.minimum.reduceat(self.chain_scores[self._order], self._heads)  # each movement's best take
        ranked = tuple(sorted(zip(self.movements, self.scores.tolist()), key=lambda kv: (kv[1], kv[0])))
        limit = self.answer.decision.threshold()
        nearest, score = ranked[0] if ranked else (None, np.inf)
        if nearest in self.stillness.still:  # it scores 1 whatever is shown: how little was there to explain
            score, limit, measure = self.moving, self.stillness.limit, self.stillness.measure
        else:
            measure = self.answer.decision.measure
        if nearest == self.committed and score <= limit:
            return self.commitment
        if self.committed is not None:  # it does not stand: the demonstration did not end where it does
            self.committed, self.deviated, self.deviated_at = None, True, frames
        if nearest is None or score > limit:
            return Match.unknown("no prediction fits", nearest=nearest, score=score, threshold=limit,
                                 measure=measure, candidates=ranked)
        confidence = max(0.0, 1.0 - score / limit) if limit > 0 and np.isfinite(limit) else 1.0
        return Match(nearest, confidence, None, candidates=ranked, score=score, threshold=limit, measure=measure)

    def match(self, motion: Recording) -> Match:
        """A whole segment at once: followed sample by sample, as it would have been live."""
        with one_thread():
            return self._match(motion)

    def _match(self, motion: Recording) -> Match:
        world = motion.world if motion.world is not None else motion.positions
        self.begin(motion.fps)
        self.add(world, motion.visible)
        return self.learned(motion, self.conclude(motion.n_frames))

    def learned(self, motion: Recording, answer: Match | None) -> Match | None:
        """``answer`` at the end of the demonstration ``motion``; an unknown one learned as a new movement when
        this forward model learns (:class:`~plugins.matchers.forward_model.learning.TakeLearning`)."""
        if self.learning is None or answer is None or answer.movement is not None or answer.stop \
                or not self._samples:
            return answer
        return self.learning.learn(motion, answer)


class Streaming:
    """:class:`Following` as the watching loop drives a streaming matcher (:class:`toolkit.components.Matcher`):
    ``begin`` at a segment's onset, ``observe`` after each frame, ``replay`` for rows given at once, ``conclude`` at
    its end; each commitment or deviation at the frame it was decided (``Match.decided_at``), reported when the
    rows are taken in (every :data:`BLOCK` seconds). ``observe`` returns one answer a frame: when a block decided
    more (a deviation and the commitment that replaces it), the others follow at the next frames."""

    def __init__(self, following: Following) -> None:
        self.following = following
        self.memory = None
        self.given = 0
        self.block = 1
        self.pending: list[tuple[int, Match]] = []  # decided, not told yet
        self.told: Match | None = None  # the last commitment told

    def begin(self, memory) -> None:
        self.memory, self.given, self.pending, self.told = memory, 0, [], None
        self.following.begin(memory.fps)
        self.block = max(1, int(round(BLOCK * memory.fps)))

    def _tell(self, events: list[tuple[int, Match]]) -> list[tuple[int, Match]]:
        for _, match in events:
            if not match.stop:
                self.told = match
        return events

    def _take(self, memory, every: bool = False) -> list[tuple[int, Match]]:
        """The rows of ``memory`` not given yet, once :data:`BLOCK` seconds of them have come (``every``: all of
        them now); what they decided, at their rows of working memory."""
        if memory is not self.memory:
            self.begin(memory)
        n = memory.n
        if n <= self.given or (not every and n - self.given < self.block):
            return []
        world, visible = memory.world[self.given : n], memory.visible[self.given : n]
        self.given = n
        with one_thread():
            events = self.following.add(world, visible)
        return [(memory.start + min(frame, n - 1), match) for frame, match in events]

    def observe(self, memory) -> Match | None:
        self.pending += self._take(memory)
        return self._tell([self.pending.pop(0)])[0][1] if self.pending else None

    def replay(self, memory, stop: int) -> list[tuple[int, Match]]:
        if memory is not self.memory:
            self.begin(memory)
        memory.feed(stop)
        events, self.pending = self.pending + self._take(memory), []
        return self._tell(events)

    def settled(self) -> int | None:
        return None

    def conclude(self, motion: Recording) -> Match | None:
        if self.memory is None:  # concluded without having followed the segment: all of it now
            return self.following.match(motion)
        try:
            self._take(self.memory, every=True)  # the rows not taken in yet
            with one_thread():
                final = self.following.conclude(motion.n_frames)
            if final is self.told:
                return None  # the commitment told stands
            return self.following.learned(motion, final)  # the answer at the end, or a commitment not told yet
        finally:
            self.memory, self.pending = None, []

    def inspect(self, shown: int = 5) -> dict[str, Any]:
        """The segment followed last, as the forward model's views read it: each movement's score at every sample
        (``trace``, for the movements among the ``shown`` best at some sample), the commitment and when it came (frames
        seen), whether and when it deviated, the threshold both are held to and what it measures."""
        f = self.following
        trace = getattr(f, "trace", [])
        scores = trace[-1][1] if trace else np.full(len(f.movements), np.inf)
        kept = sorted({int(i) for _, s in trace for i in np.argsort(s, kind="stable")[:shown] if np.isfinite(s[i])})
        limit = f.decision.threshold()
        return {"committed": f.committed, "committed_path": (f.committed,) if f.committed else (),
                "deviated": f.deviated, "committed_at": getattr(f, "committed_at", None) if f.committed else None,
                "deviated_at": getattr(f, "deviated_at", None), "scores": dict(zip(f.movements, scores.tolist())),
                "trace": tuple((frame, {(f.movements[i],): float(s[i]) for i in kept if np.isfinite(s[i])})
                               for frame, s in trace),
                "threshold": limit, "deviation": limit, "measure": f.decision.measure, "unit": "",
                "predicting": "the takes it learned"}
