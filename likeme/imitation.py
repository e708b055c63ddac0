"""Imitation of a recording, written out: the Python API of ``likeme imitate``.

An observer composed from a body profile and a folder of labelled clips (:func:`toolkit.observe.compose_observer`,
as ``likeme observe`` composes it) watches a demonstration, recognises each segment its segmenter closes, and
performs what it recognised with its own movements at the demonstrator's timing; what it does not know it learns
(true imitation, Buchsbaum & Blumberg 2005 §7.3, Kopp & Graeser 2006 §4.3) and performs as the demonstrator did it
(:func:`plugins.action.imitation.imitate_motion` does the imitating)::

    from likeme.imitation import imitate, save_learned, write_motion

    result = imitate("profile.toml", "repertoire", "demo.bvh")
    write_motion(result.motion, result.profile, "imitation.bvh")     # the observer's skeleton: BVH or CSV
    save_learned(result, "repertoire")                                # learned-1/demo.bvh ... beside the others

The output is in the observer's skeleton as its body profile knows it: one joint per tracked part (the profile's
source joint names), parented along the profile's ``bones`` from the root, in the profile's units and up axis, so
that reading it back through the same profile gives the imitation's part positions.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.errors import ConfigError
from toolkit.motion import Motion
from toolkit.recordings.profile import UP_AXES, BodyProfile, load_profile

__all__ = ["Imitation", "imitate", "skeleton", "write_motion", "save_learned", "segment_rows", "OUTPUT_SUFFIXES"]

OUTPUT_SUFFIXES = (".bvh", ".csv")
"""What an imitation is written as, by the suffix of the file named."""


@dataclass(frozen=True)
class Imitation:
    """What :func:`imitate` returns: the imitation (:class:`plugins.action.imitation.RecordedImitation`'s fields)
    and the profile it is in.

    ``motion``: the observer's world positions (frames, parts, 3), metres, +y up, at the demonstration's frame rate;
    ``segments``: what was performed where; ``learned``: movement name -> the clip it was learned from (world
    positions); ``demonstration``: the demonstration as it was read; ``source``: its file.
    """

    motion: Motion
    segments: tuple
    learned: dict[str, Motion]
    demonstration: Motion
    profile: BodyProfile
    source: Path

    def error(self, *, segments_only: bool = True) -> float:
        """How far the imitation's poses are from the demonstrator's, in the observer's body sizes
        (:func:`plugins.action.imitation.imitation_error`), over the segments (``segments_only``) or every frame."""
        from plugins.action.imitation import imitation_error

        frames = None
        if segments_only:
            frames = np.zeros(self.motion.n_frames, dtype=bool)
            for seg in self.segments:
                frames[seg.start : seg.end] = True
            if not frames.any():
                return float("nan")
        return imitation_error(self.motion, self.demonstration, self.profile.body, frames)


def imitate(profile: str | Path | BodyProfile, repertoire: Any, demonstration: str | Path | Motion, *,
            segmenter: str | None = None, matcher: str | None = "", correspondence: str | None = "",
            template: str | Path | None = None, settings: Mapping[str, Mapping[str, Any]] | None = None,
            learn: bool = True, transition: float = 0.2, fps: float | None = None,
            lengths_for_height: float | None | str = "", demonstration_profile: str | Path | BodyProfile | None = None,
            timing: str = "duration", pm: Any = None) -> Imitation:
    """The demonstration imitated by the observer ``likeme observe`` composes with these arguments.

    Parameters
    ----------
    profile : path or BodyProfile
        The body profile of the demonstration and of the repertoire's clips.
    repertoire : path, ClipFolder or ClipRepertoire
        The observer's own movements: a folder with one sub-folder of clips per movement.
    demonstration : path or Motion
        A recording (BVH, CSV, .npy) read through ``profile``, or world positions of its parts.
    segmenter, matcher, correspondence, lengths_for_height, template, settings
        As :func:`toolkit.observe.compose_observer` (``template=None``: ``characters/observers/recordings.toml``).
    learn : bool
        Learn a segment that is unknown as a new movement (the matcher's own learning, its ``learn`` parameter:
        ``path-search`` and ``forward-model`` name them ``learned-1``, ``learned-2``...). Without, an unknown segment is left standing in
        the hub.
    transition : float
        Seconds over which each join between movements and hubs is blended.
    fps : float, optional
        The frame rate of recordings without one of their own.
    timing : str
        How each recognised movement is timed to its segment: ``"duration"`` (played evenly over it, the speed
        re-parameterised, K&G §4.4) or ``"aligned"`` (time-warped onto the demonstrator's poses, pose by pose).
    demonstration_profile : path or BodyProfile, optional
        The body profile the demonstration is read through when it was recorded with another skeleton than the
        observer's (another suit, another naming, a tracker): it must give the same parts (by name; their order may
        differ). The imitation is in ``profile``'s skeleton all the same.
    """
    from toolkit import create_plugin_manager
    from toolkit.config.observer_templates import OBSERVER_TEMPLATE
    from toolkit.observe import Observer, compose_observer

    from plugins.action.imitation import TIMINGS, imitate_motion

    if timing not in TIMINGS:
        raise ConfigError(f"timing {timing!r}", key=("timing",), expected="a timing", available=sorted(TIMINGS))
    if not (isinstance(transition, (int, float)) and np.isfinite(transition) and transition >= 0):
        raise ConfigError(f"transition {transition!r}", key=("transition",), expected="seconds, 0 or more")
    pm = pm if pm is not None else create_plugin_manager()
    profile = profile if isinstance(profile, BodyProfile) else load_profile(profile)
    template = OBSERVER_TEMPLATE if template is None else template
    settings = _learning(pm, {k: dict(v) for k, v in (settings or {}).items()}, learn, matcher, template)
    character = compose_observer(pm, profile, repertoire, segmenter=segmenter, matcher=matcher,
                                 correspondence=correspondence, settings=settings, template=template,
                                 lengths_for_height=lengths_for_height)
    if isinstance(demonstration, Motion):
        motion, source = demonstration, Path("<motion>")
    else:
        source = Path(demonstration)
        theirs = profile if demonstration_profile is None else demonstration_profile \
            if isinstance(demonstration_profile, BodyProfile) else load_profile(demonstration_profile)
        motion = _in_parts(theirs.read(source, fps), profile, theirs)
    if motion.n_frames < 2:
        raise ConfigError(f"{motion.n_frames} frame(s)", file=source, expected="a demonstration of two frames or more")
    done = imitate_motion(Observer(character, profile.body, motion.fps), motion, transition=float(transition),
                          timing=TIMINGS[timing]())
    return Imitation(done.motion, done.segments, done.learned, done.demonstration, profile, source)


def _in_parts(motion: Motion, profile: BodyProfile, theirs: BodyProfile) -> Motion:
    """A demonstration read through another profile, its columns in ``profile``'s parts (the same names)."""
    if tuple(motion.parts) == tuple(profile.body.parts):
        return motion
    missing = [p for p in profile.body.parts if p not in motion.parts]
    if missing:
        raise ConfigError(f"the demonstration's profile has no part {missing[0]!r}", file=theirs.file,
                          key=("parts",), expected=f"the observer's parts ({profile.name}): "
                          f"{', '.join(profile.body.parts)}", available=list(motion.parts))
    index = [list(motion.parts).index(p) for p in profile.body.parts]
    return Motion(motion.positions[:, index], motion.fps, profile.body.parts, motion.visible[:, index])


def _learning(pm: Any, settings: dict, learn: bool, matcher: str | None, template: Any) -> dict:
    """``settings`` with the matcher's ``learn`` parameter set to ``learn`` when the matcher has one (a
    ``matcher.learn`` given in ``settings`` wins); a matcher without one never learns."""
    from toolkit.observe import observer_tables

    name = observer_tables(pm, matcher=matcher, template=template)[1].get("matcher", {}).get("plugin")
    if name is None:
        raise ConfigError("no matcher", key=("matcher",), expected="a matcher: imitation performs what it recognises")
    if any(p.name == "learn" for p in pm.registry.get("matcher", name).parameters):
        settings.setdefault("matcher", {}).setdefault("learn", bool(learn))
    return settings


def skeleton(profile: BodyProfile) -> tuple[list[str], list[int], list[int]]:
    """The observer's skeleton as its profile knows it: joint names (each mapped source joint once), each joint's
    parent (-1 for the root; along the profile's ``bones`` from the root, a part no bone reaches a child of the
    root), and the part whose positions each joint takes; depth first from the root, the order of a BVH file."""
    from plugins.lib.body_size import bone_tree

    body = profile.body
    tree = bone_tree(body.parts, body.bones, body.parts[body.root_index])
    parent_of = {int(c): int(p) for p, c in tree}
    children: dict[int, list[int]] = {}
    for i in range(body.n_parts):
        if i != body.root_index:
            children.setdefault(parent_of.get(i, body.root_index), []).append(i)
    order, stack = [], [body.root_index]
    while stack:  # depth first, as a BVH file lists its joints (the order of its channels)
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children.get(i, [])))
    names: list[str] = []
    parents: list[int] = []
    parts: list[int] = []
    joint_row: dict[str, int] = {}
    for i in order:
        joint = profile.joints[i]
        if joint in joint_row:  # two parts on one joint: written once
            joint_row.setdefault(body.parts[i], joint_row[joint])
            continue
        p = parent_of.get(i, body.root_index if i != body.root_index else -1)
        joint_row[joint] = len(names)
        joint_row.setdefault(body.parts[i], len(names))
        names.append(joint)
        parents.append(-1 if p < 0 else joint_row[profile.joints[p]])
        parts.append(i)
    return names, parents, parts


def write_motion(motion: Motion, profile: BodyProfile, path: str | Path) -> Path:
    """Write world positions of ``profile``'s parts as a recording of its skeleton (:func:`skeleton`), in its units
    and up axis: ``.bvh`` (position channels, :mod:`toolkit.recordings.bvh_writer`) or ``.csv`` (``JOINT_x``... with
    a ``time`` column). Reading the file back through ``profile`` gives ``motion``'s positions."""
    from toolkit.recordings.bvh_writer import from_joint_positions, write_bvh
    from toolkit.state import write_atomic

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise ConfigError(f"cannot write {path.name!r}", file=path, expected="a file name ending in "
                          + " or ".join(OUTPUT_SUFFIXES), available=list(OUTPUT_SUFFIXES))
    names, parents, parts = skeleton(profile)
    source = (np.asarray(motion.positions, dtype=float) @ UP_AXES[profile.up]) / profile.scale
    joints = source[:, parts]
    if not np.isfinite(joints).all():
        joints = np.where(np.isfinite(joints), joints, 0.0)
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".bvh":
        return write_bvh(from_joint_positions(names, parents, joints, motion.fps, str(path)), path)
    header = ["time"] + [f"{n}_{a}" for n in names for a in "xyz"]
    rows = np.column_stack([np.arange(len(joints)) / motion.fps, joints.reshape(len(joints), -1)])
    write_atomic(path, "\n".join([",".join(header)] + [",".join(repr(float(v)) for v in row) for row in rows]) + "\n")
    return path


def save_learned(result: Imitation, folder: str | Path, *, suffix: str = ".bvh") -> list[Path]:
    """Each movement learned in ``result`` written into ``folder`` as a repertoire holds it: ``folder/NAME/STEM.bvh``
    (``STEM`` the demonstration's name), in the observer's skeleton (:func:`write_motion`). ``folder`` may be the
    repertoire itself: the observer then knows the movements next time. A movement folder that exists already is
    refused (nothing is written over)."""
    folder = Path(folder)
    stem = result.source.stem if result.source.name != "<motion>" else "demonstration"
    for name in result.learned:
        if (folder / name).exists():
            raise ConfigError(f"movement folder {name!r} exists already", file=folder / name,
                              expected="a new movement: rename or remove the folder")
    return [write_motion(clip, result.profile, folder / name / f"{stem}{suffix}")
            for name, clip in result.learned.items()]


def segment_rows(result: Imitation) -> list[dict[str, Any]]:
    """The segments as ``likeme imitate --json`` reports them."""
    fps = result.motion.fps
    return [{"start_frame": s.start, "end_frame": s.end, "start_s": round(s.start / fps, 3),
             "end_s": round(s.end / fps, 3), "movement": s.movement, "learned": s.learned,
             "confidence": round(s.confidence, 3)} for s in result.segments]

