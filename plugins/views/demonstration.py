"""Demonstrations for the views: a character performs movements, and another watches them as recorded poses.

Not a component: the helpers the views share to make a demonstration (one
movement, or several with rests between them, optionally with observation
noise) and to let a character watch it outside a world, through the
``motion-capture`` perception (perfect tracking, root-relative by Buchsbaum &
Blumberg 2005, §5.1), with its own segmenter and matcher, frame by frame as
:class:`toolkit.observe.Observer` streams any recording.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from toolkit import ConfigError, Motion, load_character
from toolkit.motion import concatenate
from toolkit.recordings.segments import read_segments, segments_of

__all__ = ["Demonstration", "demonstration", "perform_sequence", "recording", "require", "watch"]


@dataclass(frozen=True)
class Demonstration:
    """Movements performed one after another: who performed them (name and body), the motion (body frame), and where
    each lies.

    ``truth`` holds ``(start_frame, end_frame, movement)`` per movement, end exclusive.
    """

    who: str
    motion: Motion
    truth: tuple[tuple[int, int, str], ...]
    body: Any = None


def require(character: Any, kind: str, plugin: str, key: str = "--view") -> Any:
    """The character's component of ``kind`` (``"segmenter"``, ``"matcher"``, ``"motor"``) if it is ``plugin``;
    else a :class:`ConfigError` naming what it has (``key``: the option or parameter that asked for it)."""
    component = getattr(character, kind, None)
    if component is None or getattr(component, "name", None) != plugin:
        have = repr(component.name) if component is not None else "none"
        raise ConfigError(f"{character.name} has no {plugin} {kind} (its {kind} is {have})", key=(key,),
                          expected=f"a character whose [{kind}] plugin is {plugin}")
    return component


def _performer(character: Any, demonstrator: str, movements: Sequence[str], key: str) -> Any:
    who = load_character(demonstrator, character.pm) if demonstrator else character
    known = who.motor.movements()
    for movement in movements:
        if movement not in known:
            raise ConfigError(f"unknown movement {movement!r}", key=(key,), expected=f"a movement of {who.name}",
                              available=sorted(known))
    return who


def demonstration(character: Any, demonstrator: str, movement: str, key: str, *, speed: float = 1.0) -> tuple[str, Motion]:
    """A movement performed by ``demonstrator`` (a character file or name; empty: ``character``), root-relative,
    as an observer would see it with perfect tracking: (the demonstrator's name, the motion).

    ``key`` names the view parameter in the error for an unknown movement.
    """
    who = _performer(character, demonstrator, [movement], key)
    return who.name, who.motor.perform(movement, speed=speed).root_relative(who.body.root)


def perform_sequence(character: Any, demonstrator: str, movements: Sequence[str], key: str, *, speed: float = 1.0,
                     rest: float = 0.5, noise: float = 0.0, seed: int = 0, fps: float = 30.0) -> Demonstration:
    """``movements`` (empty: the whole repertoire) performed one after another by ``demonstrator`` (empty:
    ``character``), holding still for ``rest`` seconds before, between and after them, with Gaussian observation
    noise of ``noise`` metres.

    The motion is in the demonstrator's body frame, which serves as the world a recording would be in.
    """
    who = _performer(character, demonstrator, movements, key)
    movements = list(movements) or who.motor.movements()
    if not movements:
        raise ConfigError(f"{who.name} has no movements to perform", key=(key,), expected="a list of one or more movements")
    hold = max(1, int(round(rest * fps)))
    parts = who.body.parts

    def still(pose: np.ndarray) -> Motion:
        return Motion(np.repeat(pose[None], hold, axis=0), fps, parts)

    pieces = [still(np.asarray(who.motor.rest_pose(), dtype=float))]
    truth, frame = [], hold
    for movement in movements:
        motion = who.motor.perform(movement, speed=speed, fps=fps)
        truth.append((frame, frame + motion.n_frames, movement))
        pieces += [motion, still(motion.positions[-1])]
        frame += motion.n_frames + hold
    motion = concatenate(pieces)
    if noise > 0:
        rng = np.random.default_rng(seed)
        motion = Motion(motion.positions + rng.normal(0.0, noise, motion.positions.shape), fps, parts)
    return Demonstration(who.name, motion, tuple(truth), who.body)


def recording(profile: Any, path: Any) -> Demonstration:
    """A recording read through a body profile (:class:`~toolkit.recordings.profile.BodyProfile`) as a demonstration to watch:
    its world positions, and its true segments from ``NAME.segments.csv`` beside it when there is one (the format
    of the benchmarks' streams, :mod:`toolkit.recordings.segments`), else none."""
    path = Path(path)
    motion = profile.read(path)
    truth = segments_of(path)
    segments = tuple((s, min(e, motion.n_frames), m) for s, e, m in read_segments(truth)
                     if s < motion.n_frames) if truth.is_file() else ()
    return Demonstration(path.name, motion, segments, profile.body)


def watch(character: Any, demo: Demonstration, each: Callable[[Any], None] | None = None) -> tuple[Any, list[Any]]:
    """``character`` watches ``demo`` through ``motion-capture`` with its own segmenter and matcher, frame by frame.

    The demonstrator's parts are perceived with the demonstrator's body and taken by name onto the watcher's own
    (the watching loop does it; a part the demonstrator lacks is never seen). ``each`` is called with every
    observation the moment its segment closes (while the segmenter and matcher still hold what they made of that
    segment: their ``inspect()``). Returns the :class:`~toolkit.observe.Observer` (its ``poses`` and ``visible``
    hold what was perceived, in the watcher's parts) and the observations.
    """
    from toolkit.observe import Observer

    perception = character.pm.registry.get("perception", "motion-capture")()
    observer = Observer(character, demo.body or character.body, demo.motion.fps, perception=perception,
                        keep=None)  # every row: the views plot the whole demonstration
    motion = demo.motion
    found: list[Any] = []
    for f in range(motion.n_frames + 1):
        closed = observer.push(motion.positions[f], motion.visible[f]) if f < motion.n_frames else observer.flush()
        for observation in closed:
            if each is not None:
                each(observation)
            found.append(observation)
    return observer, found
