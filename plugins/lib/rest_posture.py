"""Rest posture: where a body dwells, estimated online from the poses seen so far.

Buchsbaum & Blumberg 2005 (§4.1, §5.1) build everything on the *hub*, the posture movements start from and return
to, and take the observer's own hub as the demonstrator's: the hub-threshold segmenter measures how far the other
is from it, and path search compares the other's poses with one's own. A real person stands their own way
(stooped, wide-legged, proud), so their rest already looks like a movement. Kopp & Graeser 2006 (§6) name the same
gap. This module estimates the demonstrator's own rest posture from where they dwell, so that movement can be
measured from *their* rest and mapped onto *one's own* hub.

Dwelling is being slow for a while. Each frame's speed is the mean speed of the body's visible parts, smoothed over
``window`` seconds (a turning point of a gesture is slow for an instant, a stance for a while), and a frame
weighs ``1 / (speed + dwell_speed)^2``: the slower the body, the more the pose says about its rest. The rest
posture is the weighted mean of the poses seen, forgetting with time constant ``memory`` seconds, so a
demonstrator who changes stance is followed. Everything is causal (a frame's estimate uses that frame and the ones
before) and runs in O(1) memory, vectorised over a block of frames with :func:`scipy.signal.lfilter`.

``dwell_speed`` is in the observed body's own size per second (:func:`plugins.lib.body_size.body_scale`), so the
same setting holds for a mouse and a giant.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RestPosture", "DwellingRest", "dwell_weights"]


def dwell_weights(speed: np.ndarray, dwell_speed: float) -> np.ndarray:
    """How much each frame says about the rest posture: ``exp(-(speed / dwell_speed)^2 / 2)`` (1 when still)."""
    return np.exp(-0.5 * (np.asarray(speed, dtype=float) / dwell_speed) ** 2)


class RestPosture:
    """The running estimate of one demonstrator's rest posture (see the module).

    Parameters
    ----------
    n_parts : int
    fps : float
    dwell_speed : float
        Speed (body sizes per second, the same units as the speeds given) at which a frame's weight has fallen to a
        quarter of a still frame's.
    window : float
        Seconds over which the speed is smoothed (a causal moving average).
    memory : float
        Time constant (s) with which old poses are forgotten; ``inf`` keeps them all.
    """

    def __init__(self, n_parts: int, fps: float, *, dwell_speed: float, window: float, memory: float,
                 prior: np.ndarray | None = None) -> None:
        self.fps = float(fps)
        self.dwell_speed = float(dwell_speed)
        self.decay = 1.0 if not np.isfinite(memory) else float(np.exp(-1.0 / (memory * self.fps)))
        self.taps = max(1, int(round(window * self.fps)))
        self._speeds = np.zeros(0)  # the last taps - 1 speeds, for the moving average across blocks
        self._last: np.ndarray | None = None  # the last pose seen (P, 3)
        self._sum = np.zeros(n_parts * 3) if prior is None else np.asarray(prior, dtype=float).reshape(-1).copy()
        self._weight = 0.0 if prior is None else 1.0

    @property
    def current(self) -> np.ndarray | None:
        """The estimate after the last frame given (P, 3); ``None`` before the first (and without a prior)."""
        return None if self._weight <= 0 else (self._sum / self._weight).reshape(-1, 3)

    def update(self, poses: np.ndarray, visible: np.ndarray, size: float) -> np.ndarray:
        """The rest posture after each frame of a block (n, P, 3): poses (n, P, 3) hidden parts held, masks (n, P),
        ``size`` the body's size (m) that speeds are measured in."""
        from scipy.signal import lfilter

        poses = np.asarray(poses, dtype=float)
        n, p = poses.shape[:2]
        if n == 0:
            return poses.copy()
        before = poses[:1] if self._last is None else self._last[None]
        step = np.linalg.norm(np.diff(np.concatenate([before, poses]), axis=0), axis=-1)  # (n, P)
        seen = np.asarray(visible, dtype=bool) & np.isfinite(step)
        with np.errstate(invalid="ignore"):
            raw = np.where(seen.any(axis=1), np.where(seen, step, 0.0).sum(axis=1) / np.maximum(seen.sum(axis=1), 1),
                           np.nan) * self.fps / max(size, 1e-9)
        if self._last is None:
            raw[0] = np.nan  # no speed at the very first frame: it counts as still as any
        history = np.concatenate([self._speeds, raw])
        speed = _moving_mean(history, self.taps)[len(self._speeds):]
        self._speeds = history[-(self.taps - 1):] if self.taps > 1 else np.zeros(0)
        speed = np.where(np.isfinite(speed), speed, 0.0)
        w = dwell_weights(speed, self.dwell_speed)
        flat = np.nan_to_num(poses.reshape(n, p * 3))
        a = [1.0, -self.decay]
        sums, _ = lfilter([1.0], a, w[:, None] * flat, axis=0, zi=(self.decay * self._sum)[None])
        weights, _ = lfilter([1.0], a, w, zi=[self.decay * self._weight])
        self._sum, self._weight = sums[-1].copy(), float(weights[-1])
        self._last = poses[-1].copy()
        return (sums / weights[:, None]).reshape(n, p, 3)


def _moving_mean(x: np.ndarray, taps: int) -> np.ndarray:
    """The mean of the last ``taps`` finite values up to each (fewer at the start; NaN with none)."""
    finite = np.isfinite(x)
    c = np.concatenate([[0.0], np.cumsum(np.where(finite, x, 0.0))])
    k = np.concatenate([[0], np.cumsum(finite)])
    i = np.arange(1, len(x) + 1)
    lo = np.maximum(0, i - taps)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(k[i] - k[lo] > 0, (c[i] - c[lo]) / np.maximum(k[i] - k[lo], 1), np.nan)


class DwellingRest:
    """The demonstrator's rest posture, re-anchored where they *stand* (every part stays put for a while) and return.

    :class:`RestPosture` forgets slowly (tens of seconds) and so follows a change of stance only after a long
    dwell. This estimator is for segmentation (B&B §4.1, §5.1: movements leave a hub and return to it; K&G §4.1: a
    movement is bounded by rests). The rest is one's own hub (``prior``) until the demonstrator is seen standing,
    then the mean pose of where they stand.

    *Standing* at frame ``t``: over the last ``dwell`` seconds (``t`` included) every part with a position stayed
    within ``radius`` of its own mean there (its root-mean-square deviation, the largest over the parts; hidden
    parts are held, so they do not move). A stroke's turning point is slow for an instant and its parts travel on
    either side of it, so it is not standing.

    Later stretches of standing:

    - *near* the rest (their mean within ``near`` of it, eq. 1): they are the rest (it follows sway and drift);
    - *elsewhere* (the first stance of a stooped, wide-legged or proud demonstrator too): with ``confirm`` off, they
      are the new rest at once (``dwell`` seconds after they are first seen in it). With ``confirm`` on, such a
      stretch is only a *candidate*: a gesture may hold a pose as long as any stance (a bow, a pointing hand), and
      what tells a new stance from a hold is that movements *return* to it, as to a hub. The candidate becomes the
      rest when the demonstrator stands near it again after moving (the rest "returned to"), or when they have stood
      in it for ``settle`` seconds; a stretch near the old rest drops it (it was a hold); a stretch elsewhere
      replaces it.

    :meth:`update` reports, frame by frame, the rest and where it changed: ``(b, -1, -1)`` when a stretch that began
    at frame ``b`` became the rest there, ``(c, l, b)`` when a candidate that began at ``c`` and was left at ``l`` was
    returned to by a stretch that began at ``b`` (frames count from the first frame given since construction).
    Everything is causal and the result does not depend on how the frames are packed into blocks.
    """

    def __init__(self, n_parts: int, fps: float, *, dwell: float, prior: np.ndarray,
                 positions: np.ndarray | None = None, confirm: bool = False, settle: float = 0.0) -> None:
        self.fps = float(fps)
        self.taps = max(2, int(round(dwell * self.fps)))
        self.settle = int(round(settle * self.fps)) if settle > 0 else 0
        self.confirm = bool(confirm)
        self.positions = np.ones(n_parts, dtype=bool) if positions is None else np.asarray(positions, dtype=bool)
        self.rest = np.asarray(prior, dtype=float).reshape(n_parts, 3).copy()
        self._tail = np.zeros((0, n_parts, 3))  # the last taps - 1 poses
        self._spreads = np.zeros(0)  # the last spreads, for the noise floor
        self._frame = -1
        self._run_sum: np.ndarray | None = None  # the poses summed over the standing stretch under way
        self._run_count = 0
        self._run_began = -1
        self._role = ""  # what the stretch under way is: "rest" or "candidate"
        self._candidate: np.ndarray | None = None
        self._candidate_began = self._candidate_left = -1
        self.anchored = False  # has the demonstrator been seen standing yet?

    @property
    def candidate(self) -> np.ndarray | None:
        """A stance seen held elsewhere than the rest, not yet returned to (P, 3); ``None`` without one."""
        return None if self._candidate is None else self._candidate.copy()

    def spreads(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For each frame of a block (n, P, 3): the largest root-mean-square deviation of a part from its mean over
        the last ``dwell`` seconds (m), ``inf`` until that many frames have been seen; and the size
        (:func:`plugins.lib.body_size.body_scale`) of that mean pose (m). Does not change the state."""
        poses = np.asarray(poses, dtype=float)[:, self.positions]
        tail = self._tail[:, self.positions]
        x = np.concatenate([tail, poses])
        n, k = len(poses), self.taps
        if not n:
            return np.zeros(0), np.zeros(0)
        x = np.where(np.isfinite(x), x, 0.0)  # never seen: no evidence of movement either
        c1 = np.concatenate([np.zeros((1,) + x.shape[1:]), np.cumsum(x, axis=0)])
        c2 = np.concatenate([np.zeros((1,) + x.shape[1:]), np.cumsum(x * x, axis=0)])
        end = np.arange(len(tail) + 1, len(x) + 1)  # exclusive ends of the windows of the block's frames
        begin = end - k
        ok = begin >= 0
        b = np.maximum(begin, 0)
        mean = (c1[end] - c1[b]) / k
        var = np.maximum((c2[end] - c2[b]) / k - mean * mean, 0.0).sum(axis=-1)  # (n, P')
        out = np.sqrt(var.max(axis=-1)) if var.shape[-1] else np.zeros(n)
        centred = mean - mean.mean(axis=1, keepdims=True)
        size = np.sqrt((centred * centred).sum(axis=-1).mean(axis=-1)) if mean.shape[1] >= 2 else np.zeros(n)
        return np.where(ok, out, np.inf), size

    def noise_floor(self, spreads: np.ndarray, floor: float) -> np.ndarray:
        """The smallest of the spreads (n,) over the last ``floor`` seconds up to each frame (this block's and the
        ones before: causal, whatever the blocks)."""
        from scipy.ndimage import minimum_filter1d

        window = max(1, int(round(floor * self.fps)))
        x = np.concatenate([self._spreads, np.asarray(spreads, dtype=float)])
        x = np.where(np.isfinite(x), x, np.inf)
        out = minimum_filter1d(x, window, mode="constant", cval=np.inf, origin=(window - 1) // 2)
        self._spreads = x[-(window - 1):] if window > 1 else x[:0]
        return out[len(x) - len(spreads):]

    def _near(self, a: np.ndarray, b: np.ndarray, near: float, relative: bool) -> bool:
        """eq. 1 between two poses (position parts seen in both) below ``near`` (m, or body sizes of ``b``)."""
        a, b = a[self.positions], b[self.positions]
        ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
        if not ok.any():
            return False
        d = float(np.linalg.norm(a[ok] - b[ok], axis=1).mean())
        if relative:
            c = b[ok] - b[ok].mean(axis=0)
            near = near * float(np.sqrt((c * c).sum(axis=1).mean()))
        return d < near

    def update(self, poses: np.ndarray, radius: float, *, near: float = np.inf, relative: bool = False,
               noise: float = 0.0, cap: float = np.inf, floor: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The rest after each frame of a block (n, P, 3), and where it changed (n, 3) (see the class; ``-1``
        rows where it did not). ``radius``, ``cap`` and ``near`` are in metres, or with ``relative`` in body sizes
        (of the mean pose over the last ``dwell`` seconds, and of the rest).

        With ``noise = k > 0`` the radius is at least ``k`` times the smallest spread seen over the last ``floor``
        seconds (:meth:`noise_floor`: the sway and the tracker's noise of this demonstrator when they stand). Where
        that is more than ``cap``, nobody is seen standing: standing cannot be told from the tracker's noise, and
        the rest stays where it was."""
        poses = np.asarray(poses, dtype=float)
        n = len(poses)
        rests = np.empty_like(poses)
        events = np.full((n, 3), -1, dtype=np.int64)
        if not n:
            return rests, events
        spread, size = self.spreads(poses)
        scale = size if relative else np.ones(n)
        limit = radius * scale
        if noise > 0 and floor > 0:
            with np.errstate(invalid="ignore", divide="ignore"):
                level = self.noise_floor(np.where(scale > 0, spread / np.where(scale > 0, scale, 1.0), np.inf), floor)
            wide = noise * level
            # noisier than the cap: standing cannot be told from noise, and a lucky window is no evidence
            limit = np.where(wide <= cap, np.maximum(limit, wide * scale), -np.inf)
        standing = spread <= limit
        x = np.concatenate([self._tail, poses])
        held = np.where(np.isfinite(x), x, 0.0)
        offset = len(self._tail)
        for i in range(n):
            self._frame += 1
            f = self._frame
            if not standing[i]:
                if self._role == "candidate":
                    self._candidate_left = f  # the stance is left: the body moves again
                self._run_sum, self._run_count, self._role = None, 0, ""
                rests[i] = self.rest
                continue
            if self._run_sum is None:  # a new stretch: the whole window counts
                self._run_sum = held[offset + i - self.taps + 1 : offset + i + 1].sum(axis=0)
                self._run_count = self.taps
                self._run_began = f - self.taps + 1
                mean = np.where(np.isfinite(poses[i]), self._run_sum / self._run_count, np.nan)
                if not self.confirm or self._near(mean, self.rest, near, relative):
                    self._role, self._candidate = "rest", None
                    events[i] = (self._run_began, -1, -1)
                elif self._candidate is not None and self._near(mean, self._candidate, near, relative):
                    self._role = "rest"  # returned to: the candidate was a stance
                    events[i] = (self._candidate_began, self._candidate_left, self._run_began)
                    self._candidate = None
                else:
                    self._role = "candidate"
                    self._candidate_began, self._candidate_left = self._run_began, -1
            else:
                self._run_sum = self._run_sum + held[offset + i]
                self._run_count += 1
                if self._role == "candidate" and self.settle and self._run_count >= self.settle:
                    self._role, self._candidate = "rest", None  # stood in long enough: a stance
                    events[i] = (self._run_began, -1, -1)
            mean = self._run_sum / self._run_count
            if self._role == "rest":
                self.rest = np.where(np.isfinite(poses[i]), mean, self.rest)
                self.anchored = True
            else:
                self._candidate = np.where(np.isfinite(poses[i]), mean, np.nan)
            rests[i] = self.rest
        self._tail = x[-(self.taps - 1):].copy()
        return rests, events
