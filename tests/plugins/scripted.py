"""Fixture plugin: a segmenter and matchers whose answers the test scripts.

``scripted-cuts`` closes segments at given frames; ``nearest-movement`` is a
real (tiny) batch matcher: the movement of the observer's own repertoire whose
mid-pose is nearest to the segment's mid-frame; ``early-commit`` commits after
a fixed number of frames, to test the streaming path.
"""

from __future__ import annotations

import numpy as np

from toolkit import Match, Matcher, Parameter, Segment, Segmenter, hookimpl


class ScriptedCuts(Segmenter):
    """Closes a segment at each frame listed in `cuts` (start, end pairs)."""

    name = "scripted-cuts"
    parameters = (Parameter("cuts", list, [], "[[start, end], ...] frame pairs, end exclusive."),)

    def reset(self, parts, fps):
        self.fps, self.frame = fps, -1
        self.pending = sorted(tuple(c) for c in self.params["cuts"])

    @property
    def active_since(self):
        if self.pending and self.pending[0][0] <= self.frame:
            return self.pending[0][0]
        return None

    def push(self, pose, visible):
        self.frame += 1
        out = []
        while self.pending and self.pending[0][1] == self.frame + 1:
            start, end = self.pending.pop(0)
            out.append(Segment(start, end, self.fps))
        return out

    def flush(self):
        out = [Segment(s, min(e, self.frame + 1), self.fps) for s, e in self.pending if s <= self.frame]
        self.pending = []
        return out


class NearestMovement(Matcher):
    """The own movement whose middle pose is nearest to the segment's middle frame."""

    name = "nearest-movement"

    def attach(self, owner):
        super().attach(owner)
        self.templates = {}
        root = owner.body.root_index
        for name in owner.motor.movements():
            m = owner.motor.perform(name, fps=30.0)
            mid = m.positions[m.n_frames // 2]
            self.templates[name] = mid - mid[root]

    def match(self, motion):
        mid = motion.positions[motion.n_frames // 2]
        vis = motion.visible[motion.n_frames // 2]
        if not vis.any():
            return Match.unknown("nothing visible")
        dist = {n: float(np.linalg.norm(t[vis] - mid[vis], axis=1).mean()) for n, t in self.templates.items()}
        best = min(dist, key=dist.get)
        return Match(best, confidence=float(np.exp(-dist[best] / 0.05)), details={"distances": dist})


class EarlyCommit(Matcher):
    """Commits to `movement` after `after` frames of every segment."""

    name = "early-commit"
    streaming = True
    parameters = (Parameter("movement", str, "jump"), Parameter("after", int, 5))

    def begin(self, memory):
        self.seen = 0

    def observe(self, memory):
        self.seen = memory.n
        if self.seen == self.params["after"]:
            return Match(self.params["movement"], 1.0, decided_at=self.seen)
        return None

    def conclude(self, motion):
        return None if self.seen >= self.params["after"] else self.match(motion)

    def match(self, motion):
        return Match(self.params["movement"], 0.5)


class Deviating(EarlyCommit):
    """Commits to `movement` after `after` frames, then reports a deviation after `deviate` frames: with ``stop =
    true`` (the typed field the runtime reads) or only a ``"stop"`` in its details (which it does not read)."""

    name = "deviating"
    parameters = (*EarlyCommit.parameters, Parameter("deviate", int, 10), Parameter("typed", bool, True))

    def observe(self, memory):
        self.seen = memory.n
        if self.seen == self.params["deviate"]:
            if self.params["typed"]:
                return Match(self.params["movement"], 0.0, self.seen, stop=True, reason="it sped up")
            return Match(self.params["movement"], 0.0, self.seen, details={"stop": True, "reason": "it sped up"})
        return super().observe(memory)


@hookimpl
def likeme_register_segmenters():
    return [ScriptedCuts]


@hookimpl
def likeme_register_matchers():
    return [NearestMovement, EarlyCommit, Deviating]
