"""Fixture plugin: segmenters and matchers that misbehave, one way each (the watching loop must name them).

Segmenters: ``raising-segmenter`` raises in ``push`` at frame ``at``; ``far-segment`` closes a segment that ends at
frame 1e9; ``overlapping-segments`` closes 0..20 and then 10..30; ``empty-segment`` returns a segment whose start
is its end (built past ``Segment``'s own check, as a careless plugin might); ``late-onset`` says a segment under way
began at a frame still to come. Matchers: ``bad-confidence`` answers ``movement`` with confidence ``confidence``
(NaN, 5.0...); ``stranger`` answers a movement the observer has never had; ``raising-matcher`` raises.
"""

from __future__ import annotations

from toolkit import Match, Matcher, Parameter, Segment, Segmenter, hookimpl


class _Quiet(Segmenter):
    """Closes nothing unless told: a base for the misbehaving segmenters."""

    parameters = (Parameter("at", int, 20, "The frame at which it misbehaves."),)

    def reset(self, parts, fps):
        self.fps, self.frame = fps, -1

    @property
    def active_since(self):
        return None

    def push(self, pose, visible):
        self.frame += 1
        return self.misbehave() if self.frame == self.params["at"] else []

    def misbehave(self):
        return []

    def flush(self):
        return []


class RaisingSegmenter(_Quiet):
    name = "raising-segmenter"

    def misbehave(self):
        raise RuntimeError("the segmenter broke")


class FarSegment(_Quiet):
    name = "far-segment"

    def misbehave(self):
        return [Segment(0, int(1e9), self.fps)]


class OverlappingSegments(_Quiet):
    name = "overlapping-segments"

    def misbehave(self):
        return [Segment(0, 20, self.fps)]

    def flush(self):
        return [Segment(10, 30, self.fps)]


class EmptySegment(_Quiet):
    name = "empty-segment"

    def misbehave(self):
        segment = Segment(0, 1, self.fps)
        object.__setattr__(segment, "end", 0)
        return [segment]


class LateOnset(_Quiet):
    name = "late-onset"

    @property
    def active_since(self):
        return self.frame + 5 if self.frame >= self.params["at"] else None


class BadConfidence(Matcher):
    name = "bad-confidence"
    parameters = (Parameter("movement", str, "jump"), Parameter("confidence", str, "nan"))

    def match(self, motion):
        return Match(self.params["movement"], float(self.params["confidence"]))


class Stranger(Matcher):
    name = "stranger"

    def match(self, motion):
        return Match("teleport", 0.9)


class RaisingMatcher(Matcher):
    name = "raising-matcher"

    def match(self, motion):
        raise ZeroDivisionError("division by zero")


@hookimpl
def likeme_register_segmenters():
    return [RaisingSegmenter, FarSegment, OverlappingSegments, EmptySegment, LateOnset]


@hookimpl
def likeme_register_matchers():
    return [BadConfidence, Stranger, RaisingMatcher]
