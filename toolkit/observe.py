"""Watching recorded or live poses without a world: the loop behind ``likeme observe``.

An :class:`Observer` is a character watching a stream of a body's world poses,
one frame at a time, as it would in a world (perceive, segment, match; see
:mod:`toolkit.runtime`), but fed by the caller: a motion-capture file, a
network socket, a tracker. Each segment that closes comes back as an
:class:`Observation` with the matcher's answer and the moment it decided::

    observer = Observer(character, profile.body, fps=30.0)
    for positions in live_source():            # (P, 3) world positions, NaN where unseen
        for obs in observer.push(positions):
            print(obs.segment.start, obs.match.movement, obs.decided_at)
    observer.flush()

:func:`compose_observer` builds the observing character from a body profile, a
folder of labelled clips and plugin names, as ``likeme observe`` does. The
observer never learns: matchers with a ``learn`` parameter get ``learn = false``.
Every stream (and every clip classified) is watched from the motor system's
rest state (:meth:`MotorSystem.reset`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.character import Character, compose_character
from toolkit.components import Match, Matcher, Perception, Segment
from toolkit.errors import ConfigError, PluginError
from toolkit.motion import Motion
from toolkit.profile import BodyProfile
from toolkit.runtime import ObservationLog

__all__ = ["Observation", "Observer", "compose_observer", "observe_motion"]


@dataclass(frozen=True)
class Observation:
    """One segment found in the stream and what the matcher made of it.

    ``decided_at`` is the number of frames into the segment at which the matcher
    committed (``None``: at its end); ``match`` is ``None`` without a matcher.
    """

    segment: Segment
    match: Match | None
    decided_at: int | None

    @property
    def movement(self) -> str | None:
        return self.match.movement if self.match is not None else None

    @property
    def decision_fraction(self) -> float:
        """Share of the segment seen when the matcher committed (1.0 when it waited for the end)."""
        if self.decided_at is None:
            return 1.0
        return float(min(1.0, self.decided_at / self.segment.n_frames))


class Observer:
    """A character watching a stream of world poses of ``body`` at ``fps``, frame by frame.

    ``perception`` replaces the character's own for this stream (a character that
    looks at a world through ``synthetic-vision`` can watch recordings through
    ``motion-capture``); its segmenter and matcher are the character's.

    Frames come one at a time (:meth:`push`) or as a block of the frames that have
    arrived (:meth:`push_block`, as a tracker delivers a packet or a file is read).
    Both give the same observations at the same frames: a block is perceived and
    segmented at once where the plugins can do so (``Perception.perceive_poses``,
    ``Segmenter.push_block``), then a streaming matcher is fed frame by frame as
    before, and each segment is answered at the frame its end was detected.
    """

    def __init__(self, character: Character, body: Any, fps: float, *, perception: Perception | None = None) -> None:
        perception = perception if perception is not None else character.perception
        if perception is None or character.segmenter is None:
            raise ConfigError(f"character {character.name} cannot observe", expected="a perception and a segmenter")
        if type(perception).perceive_pose is Perception.perceive_pose:  # it needs a world to look at
            pm = character.pm
            able = [n for n in pm.registry.names("perception") if pm.registry.get("perception", n).perceive_pose
                    is not Perception.perceive_pose] if pm is not None else []
            raise ConfigError(f"perception {perception.name!r} cannot watch recorded poses",
                              key=("perception", "plugin"), expected="a perception that implements perceive_pose",
                              available=able)
        self.character, self.body, self.fps, self.perception = character, body, float(fps), perception
        m = character.matcher
        # a matcher that cannot commit early is not fed frame by frame (it answers at the segment's end)
        self._streaming = m is not None and type(m).observe is not Matcher.observe
        self.reset()

    def reset(self) -> None:
        """Start a new stream: frame numbering, memory, segmenter and matcher restart; the motor system stands at rest."""
        c = self.character
        if c.motor is not None:
            c.motor.reset()
        self.perception.fps = self.fps
        self.perception.reset()
        c.segmenter.reset(self.body.parts, self.fps)
        self.memory = ObservationLog(tuple(self.body.parts), self.fps, capacity=256)
        self._early: Match | None = None
        self._open: int | None = None

    @property
    def n_frames(self) -> int:
        return self.memory.n

    @property
    def poses(self) -> np.ndarray:
        """The root-relative poses perceived so far (frames, P, 3): the working memory."""
        return self.memory.positions

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen in each frame so far (frames, P)."""
        return self.memory.visible

    def _perceive(self, positions: np.ndarray, visible: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        positions = np.asarray(positions, dtype=float)
        visible = None if visible is None else np.asarray(visible, dtype=bool)
        times = (self.memory.n + np.arange(len(positions))) / self.fps
        poses, seen = self.perception.perceive_poses(positions, visible, self.body, times)
        self.memory.extend(poses, seen)
        return poses, seen

    def push(self, positions: np.ndarray, visible: np.ndarray | None = None) -> list[Observation]:
        """One frame of world positions (P, 3); returns the observations of segments that closed here."""
        return self.push_block(np.asarray(positions, dtype=float)[None],
                               None if visible is None else np.asarray(visible, dtype=bool)[None])

    def push_block(self, positions: np.ndarray, visible: np.ndarray | None = None) -> list[Observation]:
        """Frames of world positions (n, P, 3) in the order they arrived; the observations of segments that
        closed during them (the same as pushing them one by one)."""
        first = self.memory.n
        poses, seen = self._perceive(positions, visible)
        if not len(poses):
            return []
        closed, since = self.character.segmenter.push_block(poses, seen)
        out: list[Observation] = []
        k = 0
        for i in range(len(poses)):
            while k < len(closed) and closed[k][0] == i:
                out.extend(self._close([closed[k][1]]))
                k += 1
            self._follow(int(since[i]), first + i)
        return out

    def watch(self, motion: Motion, *, block: int = 0) -> list[Observation]:
        """Stream a whole motion of world positions (reset first, flushed at the end).

        ``block``: frames delivered at a time (0: the whole motion as one block); the observations do not
        depend on it.
        """
        self.reset()
        step = block if block > 0 else max(1, motion.n_frames)
        out: list[Observation] = []
        for f in range(0, motion.n_frames, step):
            out.extend(self.push_block(motion.positions[f : f + step], motion.visible[f : f + step]))
        out.extend(self.flush())
        return out

    def classify(self, motion: Motion) -> Observation:
        """Take a whole motion of world positions as one segment: what the matcher makes of it, and when.

        The frames are perceived and fed to the matcher one by one (so a streaming matcher may commit early);
        the segmenter is not used.
        """
        c = self.character
        if c.matcher is None:
            raise ConfigError(f"character {c.name} cannot classify", expected="a matcher")
        self.reset()
        c.matcher.begin(self.fps)
        poses, seen = self._perceive(motion.positions, motion.visible)
        early = None
        if self._streaming:
            for f in range(len(poses)):
                match = c.matcher.observe(poses[f], seen[f])
                if early is None and match is not None and not match.details.get("stop"):
                    early = match
        segment = Segment(0, max(1, motion.n_frames), self.fps)
        late = c.matcher.conclude(self.memory.motion())
        return _answer(segment, early, late)

    def flush(self) -> list[Observation]:
        """End of the stream: the segment under way (if the segmenter accepts it)."""
        return self._close(self.character.segmenter.flush())

    def _follow(self, since: int, frame: int) -> None:
        """After ``frame``: feed the streaming matcher the frames of the segment under way (from its onset ``since``;
        -1: none)."""
        if since < 0 or not self._streaming:
            self._open = None if since < 0 else since
            return
        m = self.character.matcher
        if self._open != since:
            self._open, self._early = since, None
            m.begin(self.fps)
            frames = range(since, frame + 1)
        else:
            frames = range(frame, frame + 1)
        for f in frames:
            match = m.observe(self.memory.positions[f], self.memory.visible[f])
            if match is not None and self._early is None and not match.details.get("stop"):
                self._early = match

    def _close(self, closed: list[Segment]) -> list[Observation]:
        out = []
        for segment in closed:
            if not isinstance(segment, Segment):
                raise PluginError(self.character.segmenter.name, "Segmenter.push", f"returned {segment!r}")
            m = self.character.matcher
            if m is None:
                out.append(Observation(segment, None, None))
                continue
            motion = self.memory.motion(segment.start, segment.end)
            early = self._early if self._open == segment.start else None
            if early is None:  # a batch matcher, or a segmenter that only reports segments once they are over
                m.begin(self.fps)
            out.append(_answer(segment, early, m.conclude(motion)))
            self._early, self._open = None, None
        return out


def _answer(segment: Segment, early: Match | None, late: Match | None) -> Observation:
    """The matcher's answer for a segment: what it concluded at the end, else what it committed to early."""
    if late is None and early is not None:
        return Observation(segment, early, early.decided_at)
    return Observation(segment, late if late is not None else Match.unknown(), None)


def observe_motion(observer: Observer, motion: Motion) -> list[Observation]:
    """Stream a whole motion of world positions through ``observer`` (reset first) and flush it."""
    return observer.watch(motion)


def compose_observer(pm: Any, profile: BodyProfile, repertoire: str | Path, *, segmenter: str = "hub-threshold",
                     matcher: str | None = "path-search", settings: Mapping[str, Mapping[str, Any]] | None = None,
                     motor: str | None = None) -> Character:
    """The observing character: ``profile``'s body, a repertoire from the clips in ``repertoire``, named plugins.

    The motor system is the one the matcher works with (its ``motor_systems``), else ``posegraph``.
    ``settings`` holds extra parameters per table (``{"matcher": {"k": 4}}``).
    """
    settings = {k: dict(v) for k, v in (settings or {}).items()}
    if matcher is not None:
        cls = pm.registry.get("matcher", matcher)
        wanted = getattr(cls, "motor_systems", ()) or ("posegraph",)
        motor = motor or wanted[0]
        if any(p.name == "learn" for p in cls.parameters):
            settings.setdefault("matcher", {}).setdefault("learn", False)
    facing = {"left": profile.body.facing.left, "right": profile.body.facing.right}
    if profile.body.facing.forward:
        facing["forward"] = profile.body.facing.forward
    if profile.body.facing.behind:
        facing["behind"] = profile.body.facing.behind
    table: dict[str, Any] = {
        "character": {"name": "observer", "description": f"watches {profile.name} motion"},
        "body": {"parts": list(profile.body.parts), "root": profile.body.root, "facing": facing,
                 "bones": [list(b) for b in profile.body.bones]},
        "motor": {"plugin": motor or "posegraph", "clips": str(Path(repertoire).resolve()),
                  "profile": str(profile.file.resolve()) if profile.file else "", **settings.get("motor", {})},
        "perception": {"plugin": "motion-capture", **settings.get("perception", {})},
        "segmenter": {"plugin": segmenter, **settings.get("segmenter", {})},
    }
    if matcher is not None:
        table["matcher"] = {"plugin": matcher, **settings.get("matcher", {})}
    return compose_character(table, pm)
