"""Watching recorded or live poses without a world: the loop behind ``likeme observe``.

An :class:`Observer` is a character watching a stream of a body's world poses, fed by the caller: a motion-capture
file, a network socket, a tracker. It perceives each packet of frames with its perception and hands the percepts to
the character's :class:`~toolkit.watching.WatchingLoop`, the same loop an actor in a world runs (working memory,
segment, match). Each segment that closes comes back as an :class:`Observation` with the matcher's answer and the
moment it decided::

    observer = Observer(character, profile.body, fps=30.0)
    for positions in live_source():            # (P, 3) world positions, NaN where unseen
        for obs in observer.push(positions):
            print(obs.segment.start, obs.match.movement, obs.decided_at)
    observer.flush()

:func:`compose_observer` builds the observing character from a body profile, a folder of labelled clips and the
observer template ``characters/observers/recordings.toml`` (which names the perception, segmenter, matcher and motor
system used when a caller names none), as ``likeme observe`` does. The observer never learns: matchers with a
``learn`` parameter get ``learn = false``. Every stream (and every clip classified) is watched from the motor
system's rest state (:meth:`MotorSystem.reset`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.character import COMPONENT_TABLES, Character, compose_character
from toolkit.config.observer_templates import (ALTERNATIVES, OBSERVER_TEMPLATE, checked_template,
                                               read_observer_template)
from toolkit.config.search import merge_tables
from toolkit.components import Perception
from toolkit.errors import ConfigError, PluginError
from toolkit.motion import Motion
from toolkit.recordings.clips import ClipFolder
from toolkit.recordings.profile import BodyProfile
from toolkit.watching import KEEP_SECONDS, MAX_SEGMENT_SECONDS, Observation, WatchingLoop, guarded

__all__ = ["Observation", "Observer", "compose_observer", "observer_tables", "observer_plugins", "NO_CORRESPONDENCE"]

NO_CORRESPONDENCE = "none"
"""The correspondence name that means none (``--correspondence none``): the papers' plain observer."""


class Observer:
    """A character watching a stream of world poses of ``body`` at ``fps``, frame by frame or a packet at a time.

    ``perception`` replaces the character's own for this stream (a character that looks at a world through
    ``synthetic-vision`` can watch recordings through ``motion-capture``); it must declare
    ``watches_recordings``. The segmenter and matcher are the character's, run by its watching loop.

    Frames come one at a time (:meth:`push`) or as a block of the frames that have arrived (:meth:`push_block`,
    as a tracker delivers a packet or a file is read). Both give the same observations at the same frames: a block
    is perceived and segmented at once where the plugins can do so (``Perception.perceive_poses``,
    ``Segmenter.push_block``), then a streaming matcher is fed frame by frame.

    Working memory is bounded (:mod:`toolkit.watching`): it holds the segment under way and the last ``keep``
    seconds (default :data:`~toolkit.watching.KEEP_SECONDS`), and a segment still open after ``max_segment``
    seconds (default :data:`~toolkit.watching.MAX_SEGMENT_SECONDS`) is cut there, so an observer fed for hours
    stays the same size; ``keep=None`` keeps every row. :meth:`watch`, given a whole motion, keeps every row of it
    (``poses`` is then its whole perception). Every call into a plugin (the perception's included) is guarded: a
    failure is a :class:`~toolkit.errors.PluginError` naming it, and what it returns is checked.
    """

    def __init__(self, character: Character, body: Any, fps: float, *, perception: Perception | None = None,
                 keep: float | None = KEEP_SECONDS, max_segment: float | None = MAX_SEGMENT_SECONDS) -> None:
        perception = perception if perception is not None else character.perception
        if perception is None or character.segmenter is None:
            raise ConfigError(f"character {character.name} cannot observe", expected="a perception and a segmenter")
        if not perception.watches_recordings:  # it needs a world to look at
            pm = character.pm
            able = [n for n in pm.registry.names("perception")
                    if pm.registry.get("perception", n).watches_recordings] if pm is not None else []
            raise ConfigError(f"perception {perception.name!r} cannot watch recorded poses",
                              key=("perception", "plugin"), expected="a perception that implements perceive_pose",
                              available=able)
        self.character, self.body, self.fps, self.perception = character, body, float(fps), perception
        self.loop = WatchingLoop(character, keep=keep, max_segment=max_segment)
        self.reset()

    def reset(self) -> None:
        """Start a new stream: frame numbering, memory, perception and segmenter restart; the motor system stands
        at rest."""
        if self.character.motor is not None:
            guarded(self.character.motor, "reset")
        guarded(self.perception, "reset", self.fps)
        self.loop.reset(self.body.parts, self.fps, capacity=256)

    @property
    def memory(self) -> Any:
        """The working memory (:class:`~toolkit.watching.ObservationLog`), in the character's parts."""
        return self.loop.memory

    @property
    def n_frames(self) -> int:
        return self.loop.memory.n

    @property
    def poses(self) -> np.ndarray:
        """The root-relative poses perceived so far (frames, P, 3): the working memory, hidden parts held (with
        bounded working memory, the rows it holds: from frame ``memory.offset``)."""
        return self.loop.memory.positions

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen in each frame so far (frames, P) (the rows working memory holds)."""
        return self.loop.memory.visible

    def _perceive(self, positions: np.ndarray, visible: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """The perception's root-relative poses (n, S, 3) and visibility (n, S) of world positions (n, S, 3),
        guarded and checked."""
        positions = np.asarray(positions, dtype=float)
        visible = None if visible is None else np.asarray(visible, dtype=bool)
        times = (self.loop.memory.n + np.arange(len(positions))) / self.fps
        result = guarded(self.perception, "perceive_poses", positions, visible, self.body, times)
        where = f"{type(self.perception).__name__}.perceive_poses"
        try:
            poses, seen = result
            poses, seen = np.asarray(poses, dtype=float), np.asarray(seen, dtype=bool)
        except (TypeError, ValueError):
            raise PluginError(self.perception.name, where, f"returned {type(result).__name__}, expected (poses, "
                              f"visible)") from None
        if poses.shape != positions.shape or seen.shape != positions.shape[:2]:
            raise PluginError(self.perception.name, where, f"returned poses {poses.shape} and visible {seen.shape}, "
                              f"expected {positions.shape} and {positions.shape[:2]}")
        return poses, seen

    def push(self, positions: np.ndarray, visible: np.ndarray | None = None) -> list[Observation]:
        """One frame of world positions (P, 3); returns the observations of segments that closed here."""
        return self.push_block(np.asarray(positions, dtype=float)[None],
                               None if visible is None else np.asarray(visible, dtype=bool)[None])

    def push_block(self, positions: np.ndarray, visible: np.ndarray | None = None) -> list[Observation]:
        """Frames of world positions (n, P, 3) in the order they arrived; the observations of segments that
        closed during them (the same as pushing them one by one)."""
        poses, seen = self._perceive(positions, visible)
        return self.loop.push(poses, seen, np.asarray(positions, dtype=float))

    def watch(self, motion: Motion, *, block: int = 0) -> list[Observation]:
        """Stream a whole motion of world positions (reset first, flushed at the end).

        ``block``: frames delivered at a time (0: the whole motion as one block); the observations do not
        depend on it. Every row is kept (``poses`` is the whole motion's perception) and no segment is cut.
        """
        bound = self.loop.keep
        self.loop.keep = None  # the motion is whole in memory already: its perception is kept whole too
        try:
            self.reset()
            step = block if block > 0 else max(1, motion.n_frames)
            out: list[Observation] = []
            for f in range(0, motion.n_frames, step):
                out.extend(self.push_block(motion.positions[f : f + step], motion.visible[f : f + step]))
            out.extend(self.flush())
        finally:
            self.loop.keep = bound
        return out

    def classify(self, motion: Motion) -> Observation:
        """Take a whole motion of world positions as one segment: what the matcher makes of it, and when.

        The frames are perceived and fed to the matcher one by one (so a streaming matcher may commit early);
        the segmenter is not used.
        """
        if self.character.matcher is None:
            raise ConfigError(f"character {self.character.name} cannot classify", expected="a matcher")
        self.reset()
        poses, seen = self._perceive(motion.positions, motion.visible)
        return self.loop.classify(poses, seen, motion.positions)

    def flush(self) -> list[Observation]:
        """End of the stream: the segment under way (if the segmenter accepts it)."""
        return self.loop.flush()


def compose_observer(pm: Any, profile: BodyProfile, repertoire: Any, *, segmenter: str | None = None,
                     matcher: str | None = "", settings: Mapping[str, Mapping[str, Any]] | None = None,
                     motor: str | None = None, correspondence: str | None = "",
                     lengths_for_height: float | None | str = "",
                     template: str | Path | None = OBSERVER_TEMPLATE) -> Character:
    """The observing character: ``profile``'s body, a repertoire from the clips in ``repertoire``, its components
    from ``template`` (an observer template: an ``[observer]`` table and component tables, no body) unless named
    here.

    Parameters
    ----------
    repertoire : str, Path, ClipFolder or ClipRepertoire
        A folder of labelled clips, read through ``profile`` (a :class:`~toolkit.recordings.clips.ClipFolder`: give
        one object to several observers and the folder is read once), or a repertoire built in memory
        (:func:`plugins.lib.clip_repertoire.clip_repertoire`). The motor system receives it when it is attached
        (:attr:`Character.repertoire`) and reads it with its own settings; both give the same character.
    segmenter, matcher, motor : str, optional
        Plugin names replacing the template's (the template's own plugin, named, keeps its parameters);
        ``matcher=None`` composes no matcher (segmentation only). The motor
        system is the template's unless the matcher declares others (its ``motor_systems``): then its first.
    correspondence : str, optional
        A correspondence plugin replacing the template's; ``None`` or ``"none"``: none, the papers' plain
        observer, which compares the demonstrator's poses with its own as they are.
    lengths_for_height : float, optional
        The height (m) the length parameters were written for, replacing the template's: each is scaled to the
        observer's own height (:attr:`Character.length_scale`). ``None`` or 0: metres as written (the papers).
    settings : mapping, optional
        Extra parameters per table (``{"matcher": {"k": 4}}``; ``{"perception": {"plugin": ...}}`` replaces one).
    """
    head, tables = observer_tables(pm, segmenter=segmenter, matcher=matcher, settings=settings, motor=motor,
                                   correspondence=correspondence, template=template)
    facing = profile.body.facing.table()  # every left/right pair, the forward marker and its behind part
    character: dict[str, Any] = {"name": head.get("name", "observer"),
                                 "description": f"watches {profile.name} motion" + (f": {head['description']}"
                                                                                     if head.get("description") else "")}
    lengths_for = head.get("lengths_for_height") if lengths_for_height == "" else lengths_for_height
    if lengths_for:
        character["lengths_for_height"] = lengths_for
    table: dict[str, Any] = {
        "character": character,
        "body": {"parts": list(profile.body.parts), "root": profile.body.root, "facing": facing,
                 "bones": [list(b) for b in profile.body.bones]},
        **tables,
    }
    if isinstance(repertoire, (str, Path)):  # a folder, read through the profile given (never loaded again)
        repertoire = ClipFolder(Path(repertoire).resolve(), profile)
    return compose_character(table, pm, repertoire=repertoire)  # handed to the motor system as it is attached


def observer_tables(pm: Any, *, segmenter: str | None = None, matcher: str | None = "",
                    settings: Mapping[str, Mapping[str, Any]] | None = None, motor: str | None = None,
                    correspondence: str | None = "", template: str | Path | None = OBSERVER_TEMPLATE
                    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """The ``[observer]`` table of ``template`` and the component tables (``plugin`` and parameters) an observer
    composed with these arguments has, as :func:`compose_observer` takes them (its arguments, the same meaning)."""
    settings = {k: dict(v) for k, v in (settings or {}).items()}
    base = checked_template(template, pm)[0]
    tables: dict[str, dict[str, Any]] = {k: dict(v) for k, v in base.items() if k in COMPONENT_TABLES}
    for key, name in (("segmenter", segmenter), ("matcher", matcher), ("motor", motor)):
        if name and tables.get(key, {}).get("plugin") != name:  # another plugin: none of the template's parameters,
            # but its own from the template's [ALTERNATIVES.NAME] table, if any
            tables[key] = {"plugin": name, **base.get(ALTERNATIVES[key], {}).get(name, {})}
    if matcher is None:
        tables.pop("matcher", None)
    if correspondence is None or correspondence == NO_CORRESPONDENCE:
        tables.pop("correspondence", None)
        settings.pop("correspondence", None)
    elif correspondence:
        tables["correspondence"] = {"plugin": correspondence}
    if "matcher" in tables:
        cls = pm.registry.get("matcher", tables["matcher"]["plugin"])
        wanted = cls.motor_systems
        if not motor and wanted and tables.get("motor", {}).get("plugin") not in wanted:
            tables["motor"] = {"plugin": wanted[0], **base.get(ALTERNATIVES["motor"], {}).get(wanted[0], {})}
        if any(p.name == "learn" for p in cls.parameters):
            settings.setdefault("matcher", {}).setdefault("learn", False)
    for key, extra in settings.items():
        if key in tables and extra.get("plugin", tables[key].get("plugin")) != tables[key].get("plugin"):
            tables[key] = {}  # another plugin: none of the template's parameters apply
        tables[key] = merge_tables(tables.get(key, {}), extra)  # a parameter's own table merged key by key
    return dict(base["observer"]), tables


def observer_plugins(pm: Any, *, segmenters: Sequence[str] = (), matchers: Sequence[str] = (),
                     correspondence: str | None = "", template: str | Path | None = OBSERVER_TEMPLATE
                     ) -> dict[str, list[str]]:
    """The plugins each component table of an observer composed from ``template`` may have, by table: the template's,
    with the ``segmenters``, ``matchers`` and ``correspondence`` named instead of its own, and the motor system each
    of those matchers needs. What ``--set TABLE.KEY=VALUE`` is checked against before any work
    (:func:`toolkit.config.settings.check_settings`)."""
    plugins: dict[str, list[str]] = {k: [v["plugin"]] for k, v in read_observer_template(template, pm)[0].items()
                                     if isinstance(v, Mapping) and isinstance(v.get("plugin"), str)}
    if segmenters:
        plugins["segmenter"] = list(segmenters)
    if matchers:
        plugins["matcher"] = list(matchers)
    if correspondence is None or correspondence == NO_CORRESPONDENCE:
        plugins.pop("correspondence", None)
    elif correspondence:
        plugins["correspondence"] = [correspondence]
    motors = set(plugins.get("motor", []))
    for name in plugins.get("matcher", []):
        try:
            wanted = pm.registry.get("matcher", name).motor_systems
        except ConfigError as err:  # an unknown matcher is named here, listing the registered ones
            raise err.within(prefix=("--matcher",)) from None
        if wanted and not motors & set(wanted):
            motors.add(wanted[0])
    if motors:
        plugins["motor"] = sorted(motors)
    return plugins




