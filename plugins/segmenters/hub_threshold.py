"""Segmenter ``hub-threshold``: movements begin and end where the observed body leaves and returns to a hub.

Buchsbaum & Blumberg 2005, §5.1. Almost every movement of the observer's own
repertoire starts and ends in a hub (standing), so the observer compares each
incoming frame with *its own* hub pose (root-relative, from its motor system)
by eq. 1 over the visible parts, low-pass filters that distance, and marks a
segment's beginning where the filtered distance rises above a threshold and its
end where it falls back below.

Additions a real stream needs, each a parameter:

- hysteresis: the end threshold may be lower than the start threshold, so
  noise around the threshold does not chatter;
- frames with no visible part carry no evidence: the filter holds its value
  (a long dropout neither starts nor ends a movement);
- ``min_duration`` drops blips, ``max_gap`` joins a dip below the threshold
  shorter than it to the surrounding segment;
- the reported start and end are moved back by the filter's delay, so they
  mark where the raw distance crossed, not where the lagging filter did;
- noise floor: noisy observations never reach distance 0 even at rest (eq. 1
  averages norms, which noise only increases). With ``floor`` > 0 the
  threshold applies to the filtered distance minus its minimum over the last
  ``floor`` seconds, so the same threshold works for clean and noisy input.
  (A stream that starts in the middle of a movement is then not segmented
  until the body has once been at rest.)

Two more, for real people (the correspondence problem, B&B §7.1, K&G §6), each off by default so the paper's
observer is what a character gets unless it asks:

- ``reference = "rest"``: the distance is measured from *the demonstrator's own rest posture*, not from the observer's
  hub. It is estimated online and causally (:class:`plugins.lib.rest_posture.DwellingRest`): one's own hub until the
  demonstrator is seen *standing* (every part stays within ``rest.stillness`` times the start threshold of its mean for
  ``rest.stand_time`` seconds) somewhere else, then the mean pose of where they stand. When they stand near their rest
  while a segment is under way, the segment ends where the standing began. A stance away from the rest (a stooped,
  wide-legged or proud one, or a new one) must (``rest.stance = "returned"``, the default) also be *returned to*, as
  B&B's hubs are the poses movements leave and come back to: a pose held elsewhere is a candidate; when the
  demonstrator, after moving, stands near it again, it becomes the rest and the segment under way is cut in two, the
  movement into the stance (up to where they first stood in it) and the movement from it back to it (from where they
  left it); if they return to the old rest instead, it was a hold and nothing is cut. Standing in it for ``rest.settle``
  seconds makes it the rest too (the segment then ends where they first stood in it). ``rest.stance = "held"`` takes any
  held pose as the new rest at once (quicker, and a gesture's hold longer than ``rest.stand_time`` cuts it).
  ``rest.stand_time = 0.5`` s: a stroke's turning point is slow for about a tenth of a second (K&G §4.1's sensory
  memory), people pause between gestures for half a second or more. ``rest.settle = 2`` s: longer than a gesture holds a
  pose (a bow, a pointing hand: about a second), short enough for a live observer. ``rest.stillness = 0.25``: with the
  start threshold at 0.1 body sizes, every part stays within about a centimetre of where it was on a standing adult
  (0.45 m body size): standing sway (1-2 cm/s) and marker noise over half a second, far below a gesture's tens of cm/s.
  A noisier tracker (a Kinect) moves every part more than that when nobody moves, so the radius is at least ``noise =
  2`` times the smallest spread seen over the last ``floor`` seconds (what this demonstrator and this tracker show when
  they stand; the spread of a still body fluctuates around its level, a gesture's is many times larger). Where that is
  more than half the start threshold, standing cannot be told from noise and nobody is seen standing: the rest stays
  where it was (one's own hub, the paper's, if it never moved).
- ``units = "body"``: the distance is measured in the demonstrator's body sizes
  (:func:`plugins.lib.body_size.body_scale` of the reference pose: the root-mean-square distance of the parts from
  their centroid, about 0.45 m for a standing adult, 0.20 m for Max) and compared with ``body.threshold``. The
  default 0.1 is the paper's 0.02 m on Max (0.02 / 0.20), so Max watching Morris is unchanged, and the same file
  holds for a mouse, a humanoid or a Kinect skeleton whatever units its recordings are in (a Kinect's noise is
  the ``floor``'s to absorb).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np

from plugins.lib.body_size import body_scale
from plugins.lib.pose_distance import pose_distance
from plugins.lib.rest_posture import DwellingRest
from toolkit import ConfigError, Motion, Parameter, Segment, Segmenter, hookimpl
from toolkit.components import provides


class NamedPoses(Protocol):
    """A motor system whose poses have names (``key_poses``), as ``keyframe`` and ``posegraph`` have: the ``hub``
    parameter names one of them."""

    key_poses: Any
    """Named poses: ``key_poses.names`` and ``key_poses[name]``, a pose (P, 3) in the motor system's local frame."""


class HubThreshold(Segmenter):
    """Segments where the distance from the observer's own hub pose crosses a threshold (§5.1)."""

    name = "hub-threshold"
    none_found = ("hub-threshold begins a movement where the body leaves its rest (the distance from the hub pose "
                  "rising above its running minimum): a recording that begins in motion, or never rests, shows no "
                  "beginning; --segmenter velocity-direction cuts at the demonstrator's own rests and takes a "
                  "recording that never rests whole")
    parameters = (
        Parameter("threshold", float, 0.02, "Filtered eq. 1 distance (m) from the hub above which a movement has begun. "
                  "Lower finds subtler movements and more noise; higher misses small movements.", minimum=0.0, length=True),
        Parameter("release", float, 0.75, "End threshold as a fraction of `threshold` (hysteresis; 1 = none).", minimum=0.0, maximum=1.0),
        Parameter("cutoff", float, 4.0, "Low-pass cut-off frequency in Hz (second-order Butterworth). "
                  "Lower smooths more noise but delays and merges boundaries.", minimum=0.1),
        Parameter("min_duration", float, 0.25, "Segments shorter than this (s) are dropped as noise.", minimum=0.0, seconds=True),
        Parameter("max_gap", float, 0.1, "Dips below the end threshold shorter than this (s) do not end a segment.", minimum=0.0, seconds=True),
        Parameter("floor", float, 10.0, "Seconds over which the running minimum of the filtered distance is "
                  "taken as the noise floor and subtracted (0: no floor, the paper's plain threshold).", minimum=0.0, seconds=True),
        Parameter("hub", str, "", "The hub pose to compare with (default: the observer's rest pose)."),
        Parameter("reference", str, "hub", "What the distance is measured from: the observer's own hub (the paper) "
                  "or the demonstrator's own rest, re-anchored wherever they stand still for `rest.stand_time` seconds.",
                  choices=("hub", "rest")),
        Parameter("rest", doc="With reference = rest: how the demonstrator's own rest is found and followed.",
                  parameters=(
            Parameter("stand_time", float, 0.5, "Seconds every part must stay put to count as standing (a new rest). "
                      "Shorter follows a new stance sooner and cuts gestures at shorter holds.", minimum=0.05, seconds=True),
            Parameter("stance", str, "returned", "A pose held away from the rest becomes the new rest once a movement "
                      "returns to it (or it is held for `settle`), or at once when held.",
                      choices=("returned", "held")),
            Parameter("settle", float, 2.0, "With stance = returned: seconds of standing in a new stance after which "
                      "it is the rest without a return (0: only a return).", minimum=0.0, seconds=True),
            Parameter("stillness", float, 0.25, "Standing means every part stays within this share of the start "
                      "threshold of its mean pose over `stand_time`.", minimum=0.0, maximum=1.0),
            Parameter("noise", float, 2.0, "The standing radius is at least this many times the smallest spread of "
                      "the demonstrator's parts over `stand_time` seen in the last `floor` seconds (their sway and the "
                      "tracker's noise); above half the start threshold nobody is seen standing (0: `stillness` "
                      "alone).", minimum=0.0),
        )),
        Parameter("units", str, "metres", "Distances in metres against `threshold` (the paper), or in the "
                  "demonstrator's body sizes against `body.threshold`.", choices=("metres", "body")),
        Parameter("body", doc="With units = body: the thresholds in the demonstrator's body sizes (the root-mean-"
                  "square distance of the parts from their centroid in the reference pose).", parameters=(
            Parameter("threshold", float, 0.1, "The start threshold in body sizes (0.1 = the paper's 0.02 m on Max).",
                      minimum=0.0),
        )),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        motor = owner.motor
        if self.params["hub"]:
            provides(motor, NamedPoses, needed_by="hub-threshold's hub", what="a motor system with named poses",
                     key=("hub",), expected="a motor system that declares poses (keyframe, posegraph), or no hub")
            poses = motor.key_poses
            if self.params["hub"] not in poses.names:
                raise ConfigError(f"unknown hub pose {self.params['hub']!r}", key=("hub",),
                                  expected="a pose of the observer's motor system", available=list(poses.names))
            hubs = poses[self.params["hub"]][None]
        else:
            hubs = motor.hub_poses()
        hubs = np.asarray(hubs, dtype=float)
        root = owner.body.root_index
        self.templates = hubs - hubs[:, root : root + 1]  # every hub: the distance is to the nearest one
        self.template = self.templates[0]
        self.template_parts = owner.body.parts
        self._positions = ~np.asarray(getattr(owner.body, "angle_mask", np.zeros(len(self.template), bool)), bool)
        self._hub_size = body_scale(self.template, self._positions)
        import scipy.signal  # noqa: F401  the low-pass filter's: loaded now, not at the first stream's reset

    # -- streaming ---------------------------------------------------------------------

    def reset(self, parts: Sequence[str], fps: float) -> None:
        from scipy.signal import butter

        if tuple(parts) != tuple(self.template_parts):
            raise ConfigError("hub-threshold compares poses in the observer's own parts", expected=f"the parts "
                              f"{list(self.template_parts)} (the watching loop maps the observed body's parts onto "
                              f"them; Motion.onto does it by name)", available=list(parts))
        self._fps = float(fps)
        nyquist = 0.5 * self._fps
        wn = min(self.params["cutoff"] / nyquist, 0.99)
        self._b, self._a = butter(2, wn)
        self._zi: np.ndarray | None = None
        self._delay = int(round(_group_delay(self._b, self._a)))
        self._frame = -1
        self._last = np.nan
        self._window = max(1, int(round(self.params["floor"] * self._fps))) if self.params["floor"] > 0 else 0
        self._recent: deque[tuple[int, float]] = deque()  # monotonic queue of (frame, value) for the running minimum
        self._start: int | None = None
        self._below = 0
        self._on, self._off = self.thresholds
        self._rest = DwellingRest(len(self.template), self._fps, dwell=self.params["rest"]["stand_time"],
                                  prior=self.template,
                                  positions=self._positions, confirm=self.params["rest"]["stance"] == "returned",
                                  settle=self.params["rest"]["settle"]) if self.params["reference"] == "rest" else None

    @property
    def rest(self) -> np.ndarray:
        """The pose distances are measured from now (P, 3): the demonstrator's rest as estimated so far with
        ``reference = "rest"`` (one's own hub until they have been seen standing), else one's own hub."""
        return self.template.copy() if self._rest is None else self._rest.rest.copy()

    @property
    def active_since(self) -> int | None:
        return self._start

    def distance(self, pose: np.ndarray, visible: np.ndarray) -> float:
        """eq. 1 between one observed root-relative pose and the hub template (NaN if nothing visible)."""
        return float(self.distances(np.asarray(pose)[None], np.asarray(visible)[None])[0])

    def distances(self, poses: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """eq. 1 between observed root-relative poses (n, P, 3) and the nearest hub (n,); NaN where nothing is seen."""
        return _nearest(pose_distance(np.asarray(poses)[:, None], self.templates, np.asarray(visible)[:, None]), axis=-1)

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        closed, _ = self.push_block(np.asarray(pose)[None], np.asarray(visible)[None])
        return [segment for _, segment in closed]

    def push_block(self, poses: np.ndarray, visible: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """A block of frames: the distances and the low-pass filter for all of them at once, then the
        thresholds frame by frame (the same as one push per frame)."""
        raw, filtered, events = self._evidence(poses, visible)
        closed: list[tuple[int, Segment]] = []
        since = np.empty(len(raw), dtype=int)
        for i, value in enumerate(filtered.tolist()):
            self._frame += 1
            if events[i, 0] >= 0 and self._start is not None:
                closed.extend((i, segment) for segment in self._rested(*events[i].tolist()))
            closed.extend((i, segment) for segment in self._step(value))
            since[i] = -1 if self._start is None else self._start
        return closed, since

    def _rested(self, began: int, left: int, back: int) -> list[Segment]:
        """The demonstrator came to rest (reference = rest) while a segment was under way: it ends where they began
        to stand (``began``). When they came back to a stance they had stood in from ``began`` and left at ``left``
        (``back``: where they stood in it again), the segment is the movement into it and then the one from it back
        to it."""
        start = self._start
        if left < 0:
            return self._close(max(start + 1, began), "came to rest")
        out = self._close(began, "came to rest") if began > start else []
        self._start = max(start, left)
        return out + self._close(max(self._start + 1, back), "came to rest")

    def _evidence(self, poses: np.ndarray, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The distance from the reference of each frame of a block (held where nothing is seen), low-pass filtered,
        and where the rest changed at each frame (n, 3) (:meth:`DwellingRest.update`; -1: it did not). With
        reference = rest the filter restarts at the distance from the new rest where it changes (the old rest no
        longer counts)."""
        from scipy.signal import lfilter, lfilter_zi

        poses = np.asarray(poses, dtype=float)
        visible = np.asarray(visible, dtype=bool)
        finite = np.isfinite(poses).all(axis=-1)
        if not finite.all():  # a bad value is not seen, whatever the mask said (NaN, as a part not seen yet)
            visible, poses = visible & finite, np.where(finite[..., None], poses, np.nan)
        n = len(poses)
        events = np.full((n, 3), -1, dtype=np.int64)
        body = self.params["units"] == "body"
        if self._rest is None:
            dist = self.distances(poses, visible)
            if body:
                dist = dist / max(self._hub_size, 1e-12)
        else:
            on = self.params["body"]["threshold"] if body else self.params["threshold"]
            rest = self.params["rest"]
            rests, events = self._rest.update(poses, rest["stillness"] * on, near=on, relative=body,
                                              noise=rest["noise"], cap=0.5 * on, floor=self.params["floor"])
            dist = pose_distance(poses, rests, visible)
            if body:
                dist = dist / np.maximum(body_scale(rests, self._positions), 1e-12)
            events = np.where(events >= 0, np.maximum(events, 0), -1)
        raw = _hold(np.concatenate([[self._last], dist]))[1:]  # no evidence: hold
        if not n:
            return raw, raw, events
        self._last = float(raw[-1])
        changed = events[:, 0] >= 0
        cuts = [0, *[int(i) for i in np.flatnonzero(changed) if i > 0], n]
        pieces = []
        for a, b in zip(cuts, cuts[1:]):
            if self._zi is None or changed[a]:
                self._zi = lfilter_zi(self._b, self._a) * raw[a]
            piece, self._zi = lfilter(self._b, self._a, raw[a:b], zi=self._zi)
            pieces.append(piece)
        return raw, np.concatenate(pieces), events

    def _above_floor(self, value: float) -> float:
        """``value`` minus the running minimum of the last ``floor`` seconds (itself if there is no floor)."""
        if not self._window:
            return value
        while self._recent and self._recent[-1][1] >= value:
            self._recent.pop()
        self._recent.append((self._frame, value))
        while self._recent[0][0] <= self._frame - self._window:
            self._recent.popleft()
        return value - self._recent[0][1]

    def _step(self, value: float) -> list[Segment]:
        value = self._above_floor(value)
        f = self._frame
        if self._start is None:
            if value > self._on:
                self._start = max(0, f - self._delay)
                self._below = 0
            return []
        if value < self._off:
            self._below += 1
            gap = int(round(self.params["max_gap"] * self._fps))
            if self._below > gap:
                end = max(self._start + 1, f - self._below + 1 - self._delay)
                return self._close(end)
        else:
            self._below = 0
        return []

    def flush(self) -> list[Segment]:
        if self._start is None:
            return []
        return self._close(self._frame + 1, "the stream ended")

    def _close(self, end: int, reason: str = "back near a hub pose") -> list[Segment]:
        start, self._start, self._below = self._start, None, 0
        if (end - start) / self._fps < self.params["min_duration"] or end <= start:
            return []
        return [Segment(start, end, self._fps, reason)]

    # -- batch ---------------------------------------------------------------------------

    def signal(self, motion: Motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The distance-to-hub of a root-relative motion (Fig. 4): raw, low-pass filtered, and the level the
        thresholds apply to (the filtered distance minus its running minimum over ``floor`` seconds; the filtered
        distance itself without a floor). Frames with nothing visible hold the last value.
        """
        from scipy.ndimage import minimum_filter1d

        self.reset(motion.parts, motion.fps)
        raw, filtered, _ = self._evidence(motion.positions, motion.visible)
        self.reset(motion.parts, motion.fps)
        if raw.size == 0:
            return raw, raw, raw
        if not self._window:
            return raw, filtered, filtered
        w = self._window  # the running minimum of the last w frames, this one included (trailing window)
        return raw, filtered, filtered - minimum_filter1d(filtered, w, mode="nearest", origin=(w - 1) // 2)

    @property
    def thresholds(self) -> tuple[float, float]:
        """The level at which a movement begins and the level below which it ends (hysteresis): metres, or body
        sizes with units = body."""
        on = self.params["body"]["threshold"] if self.params["units"] == "body" else self.params["threshold"]
        return on, on * self.params["release"]

    def segment(self, motion: Motion) -> list[Segment]:
        self.reset(motion.parts, motion.fps)
        closed, _ = self.push_block(motion.positions, motion.visible)
        return [segment for _, segment in closed] + self.flush()


def _nearest(distances: np.ndarray, axis: int = -1) -> np.ndarray:
    """The distance to the nearest hub (NaN where nothing was visible)."""
    if distances.shape[axis] == 1:
        return np.take(distances, 0, axis=axis)
    with np.errstate(all="ignore"):
        return np.where(np.isnan(distances).all(axis=axis), np.nan, np.nanmin(np.nan_to_num(distances, nan=np.inf), axis=axis))


def _hold(x: np.ndarray) -> np.ndarray:
    """Replace NaN by the last valid value (0 before the first), vectorised."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return x
    valid = ~np.isnan(x)
    idx = np.where(valid, np.arange(len(x)), -1)
    np.maximum.accumulate(idx, out=idx)
    return np.where(idx >= 0, x[np.maximum(idx, 0)], 0.0)


def _group_delay(b: np.ndarray, a: np.ndarray) -> float:
    """Delay in frames of the filter at low frequencies (where movements live)."""
    from scipy.signal import group_delay

    _, gd = group_delay((b, a), w=[0.01])
    return float(gd[0])


@hookimpl
def likeme_register_segmenters():
    return [HubThreshold]
