"""The runtime: a world that steps in time, with actors that act and observe.

One :meth:`World.step` advances every actor by one frame:

1. *act*: an actor that is performing moves one frame along its motion; an idle
   actor asks its action system what to do (:meth:`ActionSystem.choose`) and, if
   answered, asks its motor system for the motion (:meth:`MotorSystem.perform`).
   The pose it shows is the motion's, changed by its layer if it has one
   (:meth:`Layer.apply`: a look-at turning the head toward the object of attention).
2. *observe*: an actor that watches a target perceives it and hands the percept
   to its :class:`~toolkit.watching.WatchingLoop` (the same loop an
   :class:`~toolkit.observe.Observer` runs): working memory, segment, match.
   What the loop reports becomes run events, and a recognised movement is
   interpreted and answered by the action system (interpret → respond).
3. the world announces the step through the ``likeme_world_stepped`` hook.

Every pipeline result is also recorded as an :class:`Event` in ``world.events``
and announced through the matching run-event hook, so a plugin can observe or
extend any run. Hook calls and component calls made while a world steps follow
its ``on_plugin_error`` policy.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from contextlib import nullcontext
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from toolkit.character import Character
from toolkit.components import Behaviour, Match, MovementRequest, Percept, Segment
from toolkit.errors import ConfigError, LikemeError, PluginError
from toolkit.motion import Motion, local_to_world
from toolkit.sightings import Sightings
from toolkit.watching import Listener, ObservationLog, WatchingLoop

__all__ = ["World", "Actor", "WorldObject", "Event"]


@dataclass
class WorldObject:
    """A thing in the world: cheese, a toy ball, a baton, an ice cream cone.

    Attributes
    ----------
    name : str
        Unique within the world.
    kind : str
        What the object really is (``"food"``, ``"toy"``); what a character
        *believes* it is belongs to that character.
    position : array, shape (3,)
        World position of its centre, metres.
    radius : float
        Size, for occlusion, reach and pictures.
    colour : str
        Colour code ``"#rrggbb"`` for colour-coded vision and pictures.
    held_by : str or None
        The actor holding it; its position then follows that actor.
    properties : dict
        Anything else plugins need (``{"tasty": true}``).
    """

    name: str
    kind: str
    position: np.ndarray
    radius: float = 0.05
    colour: str = "#c0c0c0"
    held_by: str | None = None
    properties: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.position = np.asarray(self.position, dtype=float).reshape(3)


def _copy_object(obj: WorldObject) -> WorldObject:
    return WorldObject(obj.name, obj.kind, obj.position.copy(), obj.radius, obj.colour, obj.held_by, dict(obj.properties))


@dataclass(frozen=True)
class Event:
    """Something that happened in a run: ``kind`` is the hook's name without ``likeme_``."""

    frame: int
    time: float
    kind: str
    actor: str
    target: str | None = None
    data: Mapping[str, Any] = field(default_factory=dict)


class Actor:
    """A character placed in a world: where it stands, what it performs, what it watches.

    Attributes
    ----------
    id : str
    character : Character
    position : array (3,)
        Ground position of the local frame's origin.
    heading : float
        Radians about +y (0 faces +z).
    target : Actor or None
        Who it watches.
    performing : MovementRequest or None
        The movement under way.
    memory : ObservationLog or None
        Working memory of what it perceived of ``target``, in its own parts (its watching loop's).
    sightings : Sightings or None
        The rest of what it perceived, on the same rows: the objects it saw and the target's perceived heading.
    performed : list of (frame, MovementRequest)
        Everything it started performing.
    """

    def __init__(self, world: World, id: str, character: Character, position: Iterable[float], heading: float) -> None:
        self.world = world
        self.id = id
        self.character = character
        self.position = np.asarray(list(position), dtype=float).reshape(3)
        self.heading = float(heading)
        self.target: Actor | None = None
        self.watch_start = 0
        self.performing: MovementRequest | None = None
        self._motion: Motion | None = None
        self._frame = 0
        self._queue: list[MovementRequest] = []
        self._posture = np.asarray(character.motor.rest_pose(), dtype=float)  # held while no motion plays
        self._started = 0  # movements started: with the frame, the key of the layered pose kept in _shown
        self._shown: tuple[tuple[int, int], np.ndarray] | None = None
        self.percepts = 0
        self.loop = WatchingLoop(character, call=self._call, listener=_Reports(self))
        self._sightings: Sightings | None = None
        self.performed: list[tuple[int, MovementRequest]] = []

    def __repr__(self) -> str:
        return f"Actor({self.id!r}, {self.character.name!r})"

    @property
    def body(self):
        return self.character.body

    @property
    def memory(self) -> ObservationLog | None:
        """Working memory of what it perceived of its target since it began watching (``None`` when not watching):
        the rows of the segment under way and the last :attr:`World.memory_seconds` (its ``offset`` is the first row
        held; ``n`` counts every frame)."""
        return self.loop.memory if self.target is not None else None

    @property
    def sightings(self) -> Sightings | None:
        """The objects it saw and the target's heading as perceived, on working memory's rows (``None`` when not
        watching)."""
        return self._sightings if self.target is not None else None

    # -- acting ----------------------------------------------------------------------

    @property
    def idle(self) -> bool:
        """Neither performing a movement nor on the way back from a stopped one."""
        return self._motion is None

    def local_pose(self) -> np.ndarray:
        """Current positions in the actor's local frame, shape (P, 3): the motion playing (changed by the
        character's layer, if any), else the posture held."""
        if self._motion is None:
            return self._posture
        return self._layered(min(self._frame, self._motion.n_frames - 1))

    def _layered(self, frame: int) -> np.ndarray:
        """The pose shown at ``frame`` of the motion playing: the motion's, or what the layer makes of it (once
        per frame of a movement; not for the way back from a stopped imitation, which performs no request)."""
        motion = self._motion
        assert motion is not None
        layer = self.character.layer
        if layer is None or self.performing is None:
            return motion.positions[frame]
        key = (self._started, frame)
        if self._shown is None or self._shown[0] != key:
            pose = self._call("layer", "apply", self, self.performing, motion, frame, self.world)
            if pose is None:
                pose = motion.positions[frame]
            elif np.shape(pose) != (len(self.body.parts), 3):
                error = PluginError(layer.name, f"{type(layer).__name__}.apply",
                                    f"returned an array of shape {np.shape(pose)}, expected None or a pose "
                                    f"({len(self.body.parts)}, 3)")
                if self.world.on_plugin_error != "skip":
                    raise error
                self._drop("layer", layer, error)  # the run goes on with the motions as they are
                pose = motion.positions[frame]
            self._shown = (key, np.asarray(pose, dtype=float))
        return self._shown[1]

    def world_pose(self) -> np.ndarray:
        """Current positions in world coordinates, shape (P, 3); finger joint angles (angle parts) as they are."""
        local = self.local_pose()
        world = local_to_world(local, self.position, self.heading)
        angles = self.body.angle_mask
        if angles.any():
            world[angles] = local[angles]
        return world

    def request(self, request: MovementRequest) -> None:
        """Perform ``request`` now if idle, else after the current movement."""
        if self.idle:
            self._start(request)
        else:
            self._queue.append(request)

    def _start(self, request: MovementRequest) -> None:
        motor = self.character.motor
        if request.movement not in motor.movements():
            raise ConfigError(
                f"{self.id} has no movement {request.movement!r}",
                expected="a movement of its motor system",
                available=motor.movements(),
            )
        motion = self._call("motor", "perform", request.movement, speed=request.speed, fps=self.world.fps)
        if motion is None:
            return
        if not isinstance(motion, Motion) or motion.parts != self.body.parts or motion.n_frames == 0:
            raise PluginError(motor.name, f"{type(motor).__name__}.perform",
                              f"returned {motion!r}, expected a Motion of at least one frame of the parts {list(self.body.parts)}")
        self._motion, self._frame, self.performing = motion, 0, request
        self._started += 1
        self.performed.append((self.world.frame, request))
        self.world.emit("movement_started", self, request=request)
        if self.character.action is not None:
            self._call("action", "performed", self, request, self.world)
        if request.imitating is not None:
            target = self.world.actors[request.imitating]
            self.world.emit("imitation_started", self, target, request=request)

    def _advance(self) -> None:
        if self._motion is not None:
            self._frame += 1
            if self._frame >= self._motion.n_frames:
                done = self.performing  # None after the way back from a stopped movement
                self._posture = self._layered(self._motion.n_frames - 1)
                self._motion, self.performing = None, None
                if done is not None and self.character.action is not None:
                    self._call("action", "completed", self, done, self.world)
                if done is not None and done.imitating is not None:
                    target = self.world.actors[done.imitating]
                    self.world.emit("imitation_stopped", self, target, movement=done.movement, reason="completed")
        if self.idle and self._queue:
            self._start(self._queue.pop(0))
        if self.idle and self.character.action is not None:
            request = self._call("action", "choose", self, self.world)
            if request is not None:
                self._start(request)

    def _call(self, key: str, method: str, *args: Any, **kwargs: Any) -> Any:
        """Call a method of one of the character's components.

        Anything but a likeme error is a :class:`PluginError` naming the component and the method. With
        ``world.on_plugin_error == "skip"`` the component is removed from the character instead, the failure
        is recorded as a ``plugin_failed`` event, and the call returns ``None``.
        """
        component = getattr(self.character, key)
        if component is None:
            return None
        try:
            return getattr(component, method)(*args, **kwargs)
        except LikemeError as exc:
            if self.world.on_plugin_error == "skip" and isinstance(exc, PluginError):
                return self._drop(key, component, exc)
            raise
        except Exception as exc:
            error = PluginError(component.name, f"{type(component).__name__}.{method}", f"{type(exc).__name__}: {exc}")
            if self.world.on_plugin_error == "skip":
                return self._drop(key, component, error)
            raise error from exc

    def _drop(self, key: str, component: Any, error: PluginError) -> None:
        setattr(self.character, key, None)
        self.world.events.append(
            Event(self.world.frame, self.world.time, "plugin_failed", self.id, None,
                  {"plugin": component.name, "where": error.where, "error": str(error)})
        )
        return None

    # -- observing -------------------------------------------------------------------

    def watch(self, target: Actor | None) -> None:
        """Start watching ``target`` (``None`` to stop); perception, working memory and segmenter restart."""
        self.target = target
        if target is None:
            return
        c = self.character
        if c.perception is None:
            raise ConfigError(
                f"{self.id} cannot watch {target.id}: character {c.name} has no [perception] table",
                expected="a perception component",
                available=c.pm.registry.names("perception") if c.pm else None,
            )
        self.watch_start = self.world.frame + 1  # the world frame of the first percept (memory row 0)
        self._call("perception", "reset", self.world.fps)
        self.loop.keep = self.world.memory_seconds  # bounded working memory: a world may run for hours
        self.loop.reset(target.body.parts, self.world.fps)
        self._sightings = Sightings(self.world.fps, keep=self.world.history_seconds)

    def _observe(self) -> None:
        """Perceive the target and hand the percept to the watching loop."""
        target, c, world = self.target, self.character, self.world
        assert target is not None
        if c.perception is None:  # dropped after failing (skip mode): the observer is blind from now on
            return
        percept: Percept | None = self._call("perception", "perceive", self, target, world)
        if percept is None:
            return
        n = len(target.body.parts)
        if (
            not isinstance(percept, Percept)
            or np.shape(percept.pose) != (n, 3)
            or np.shape(percept.visible) != (n,)
        ):
            raise PluginError(c.perception.name, f"{type(c.perception).__name__}.perceive",
                              f"returned {type(percept).__name__} with pose {np.shape(getattr(percept, 'pose', None))} and "
                              f"visible {np.shape(getattr(percept, 'visible', None))}, expected a Percept with pose ({n}, 3) "
                              f"and visible ({n},)")
        self.percepts += 1
        world.announce("likeme_target_perceived", world=world, observer=self, target=target, percept=percept)
        world_positions = percept.world if np.shape(percept.world) == (n, 3) else None
        self._see_objects(percept)
        self.loop.push(np.asarray(percept.pose, dtype=float)[None], np.asarray(percept.visible, dtype=bool)[None],
                       None if world_positions is None else np.asarray(world_positions, dtype=float)[None])

    def _see_objects(self, percept: Percept) -> None:
        """Record the objects of ``percept`` on the row working memory is about to get; a remembered object not seen
        where the eye should have seen it is gone (:meth:`Perception.in_view`)."""
        sightings, row = self._sightings, self.loop.memory.n
        if sightings is None or row != sightings.n:  # rows pushed by someone else: nothing is known of them
            sightings = self._sightings = Sightings(self.world.fps, keep=self.world.history_seconds, start=row)
        seen = percept.objects if isinstance(percept.objects, Mapping) else {}
        believed = sightings.remembered() if row else {}
        unseen = [name for name in believed if name not in seen]
        missed: list[str] = []
        if unseen:
            where = self._call("perception", "in_view", self, self.target, self.world,
                               np.array([believed[name] for name in unseen]))
            if where is not None:
                missed = [name for name, gone in zip(unseen, np.asarray(where, dtype=bool).reshape(-1)) if gone]
        heading = percept.heading
        heading = float(heading) if isinstance(heading, (int, float, np.number)) else float("nan")
        sightings.record(row, heading, seen, percept.kinds if isinstance(percept.kinds, Mapping) else {},
                         percept.sizes if isinstance(percept.sizes, Mapping) else {}, missed)
        sightings.forget(self.loop.memory.offset)

    def stop_imitation(self, target: Actor | None, reason: str) -> None:
        """Stop imitating ``target`` now (and drop queued imitations of it); announces ``imitation_stopped``."""
        if target is None:
            return
        self._queue = [r for r in self._queue if r.imitating != target.id]
        if self.performing is not None and self.performing.imitating == target.id:
            movement, frame, pose = self.performing.movement, self._frame, self.local_pose()
            self._posture = pose
            self._motion, self.performing = None, None
            back = self._call("motor", "interrupt", frame, pose, fps=self.world.fps)
            if back is not None:  # the way back to the last correct state: plays before anything else starts
                if not isinstance(back, Motion) or back.parts != self.body.parts:
                    raise PluginError(self.character.motor.name, f"{type(self.character.motor).__name__}.interrupt",
                                      f"returned {back!r}, expected None or a Motion of the parts {list(self.body.parts)}")
                if back.n_frames:
                    self._motion, self._frame = back, 0
            self.world.emit("imitation_stopped", self, target, movement=movement, reason=reason,
                            returning=0.0 if self._motion is None else round(self._motion.n_frames / self.world.fps, 3))

    def _recognised(self, segment: Segment | None, match: Match) -> None:
        """The matcher answered: announce it, then interpret and respond (§6.1, §5.3)."""
        c, target, world = self.character, self.target, self.world
        assert target is not None
        world.emit("movement_recognised", self, target, segment=segment, match=match)
        if c.action is None or not match.known:
            return
        behaviour = self._call("action", "interpret", self, target, segment, match, world)
        event = None
        if behaviour is not None:
            event = world.emit("behaviour_identified", self, target, behaviour=behaviour)
        request = self._call("action", "respond", self, target, match, behaviour, world)
        if request is not None:
            if event is not None and request.response:  # what the observer did about it, for reports
                event.data["response"] = request.response
            self.request(request)

    def _finish(self) -> None:
        """The end of the run: the segment still under way is closed."""
        if self.target is not None:
            self.loop.flush()


class _Reports(Listener):
    """What an actor's watching loop reports, turned into run events, interpretation and responses."""

    def __init__(self, actor: Actor) -> None:
        self.actor = actor

    def segment_found(self, segment: Segment) -> None:
        self.actor.world.emit("segment_found", self.actor, self.actor.target, segment=segment)

    def recognised(self, segment: Segment | None, match: Match) -> None:
        self.actor._recognised(segment, match)

    def deviated(self, match: Match) -> None:  # the committed movement deviates from the demonstration
        self.actor.stop_imitation(self.actor.target, match.reason or "deviation")


MAX_FPS = 1000.0
"""The highest frame rate a world runs at (frames per second)."""
MAX_SECONDS = 3600.0
"""The longest run, and the longest tail of a run until idle (seconds)."""
MAX_FRAMES = 432_000
"""The most frames one run steps (an hour at 120 fps): a duration times the frame rate above it is refused."""


class World:
    """Actors and objects stepping together at a fixed frame rate.

    Parameters
    ----------
    fps : float
        Frames per second of the simulation and of every motion in it.
    pm : PluginManager, optional
        Whose hooks announce run events; defaults to the plugin manager of the
        first character added.
    on_plugin_error : "stop" or "skip"
        What a failing component or hook implementation does to the run: stop it
        with a :class:`PluginError` naming the plugin and where it failed, or
        go on without it (the component is removed from its character, the
        plugin is unregistered) and record a ``plugin_failed`` event. Hook
        failures go through the plugin manager's failure policy
        (:meth:`~toolkit.manager.PluginManager.failure_policy`), so every hook,
        whoever calls it during a step, is handled the same way.
    """

    def __init__(self, fps: float = 30.0, pm: Any = None, on_plugin_error: str = "stop") -> None:
        if not 0 < fps <= MAX_FPS:
            raise ValueError(f"fps must be positive and at most {MAX_FPS:g}")
        if on_plugin_error not in ("stop", "skip"):
            raise ValueError("on_plugin_error is 'stop' or 'skip'")
        self.on_plugin_error = on_plugin_error
        self.fps = float(fps)
        self.frame = 0
        self.actors: dict[str, Actor] = {}
        self.objects: dict[str, WorldObject] = {}
        self.events: list[Event] = []
        self.pm = pm
        self.history_seconds = 120.0
        self.memory_seconds: float | None = 120.0
        """Seconds of its working memory an actor keeps beyond the segment under way and what its components still
        need (:class:`toolkit.watching.WatchingLoop`'s ``keep``), read when it begins watching; ``None``: every row
        since it began (``likeme bench watch`` matches every true segment from memory at the end)."""
        self._removed: dict[str, WorldObject] = {}
        self._policy_key: tuple | None = None
        self._policy_cm: Any = None
        self._history: dict[int, dict[str, tuple[np.ndarray, str | None]]] = {}

    @property
    def time(self) -> float:
        return self.frame / self.fps

    def __repr__(self) -> str:
        return f"World(frame {self.frame}, {self.time:.2f} s, actors {', '.join(self.actors) or 'none'})"

    def add_actor(
        self, character: Character, id: str | None = None, position: Iterable[float] = (0, 0, 0), heading: float = 0.0
    ) -> Actor:
        """Place a character in the world (``heading`` in radians)."""
        id = id or re.sub(r"[^a-z0-9]+", "-", character.name.lower()).strip("-")
        if id in self.actors:
            raise ConfigError(f"duplicate actor id {id!r}", expected="unique actor ids", available=list(self.actors))
        actor = Actor(self, id, character, position, heading)
        self.actors[id] = actor
        if self.pm is None:
            self.pm = character.pm
        return actor

    def add_object(self, obj: WorldObject) -> WorldObject:
        if obj.name in self.objects:
            raise ConfigError(f"duplicate object name {obj.name!r}", expected="unique object names", available=list(self.objects))
        self.objects[obj.name] = obj
        return obj

    def emit(self, kind: str, actor: Actor, target: Actor | None = None, **data: Any) -> Event:
        """Record an event and call the ``likeme_<kind>`` hook; the event recorded."""
        event = Event(self.frame, self.time, kind, actor.id, target.id if target else None, data)
        self.events.append(event)
        if kind == "movement_started":
            self.announce(f"likeme_{kind}", world=self, actor=actor, **data)
        elif kind in ("imitation_started", "imitation_stopped"):
            self.announce(f"likeme_{kind}", world=self, actor=actor, target=target, **data)
        else:
            self.announce(f"likeme_{kind}", world=self, observer=actor, target=target, **data)
        return event

    def announce(self, hook_name: str, **kwargs: Any) -> None:
        """Call a run-event hook through the plugin manager (traced; a failing implementation is named, or dropped
        under the world's skip policy)."""
        if self.pm is not None:
            self.pm.announce(hook_name, **kwargs)

    def _policy(self) -> Any:
        """Hook calls in the block follow ``on_plugin_error`` (a dropped hook plugin is recorded as an event)."""
        if self.pm is None:
            return nullcontext()
        key = (id(self.pm), self.on_plugin_error)
        if self._policy_key != key:  # made once per plugin manager and policy, entered every step
            self._policy_key = key
            self._policy_cm = self.pm.failure_policy(self.on_plugin_error, self._plugin_failed)
        return self._policy_cm

    def _plugin_failed(self, plugin: str, hook_name: str, error: PluginError) -> None:
        self.events.append(Event(self.frame, self.time, "plugin_failed", "", None,
                                 {"plugin": plugin, "where": hook_name, "error": str(error)}))

    def step(self) -> None:
        """Advance one frame: every actor acts, then every watching actor observes."""
        with self._policy():
            self.frame += 1
            for actor in self.actors.values():
                actor._advance()
            for obj in self.objects.values():
                if obj.held_by is not None and obj.held_by in self.actors:
                    holder = self.actors[obj.held_by]
                    obj.position = holder.world_pose()[holder.body.index(obj.properties.get("held_in", holder.body.root))]
            self._remember()
            for actor in self.actors.values():
                if actor.target is not None:
                    actor._observe()
            self.announce("likeme_world_stepped", world=self)

    def _remember(self) -> None:
        self._history[self.frame] = {n: (o.position.copy(), o.held_by) for n, o in self.objects.items()}
        self._history.pop(self.frame - int(self.history_seconds * self.fps), None)

    def objects_at(self, frame: int) -> dict[str, WorldObject]:
        """The objects as they were at a past ``frame`` (within ``history_seconds``): copies, for "what was there then".

        Objects that did not exist then are absent; a frame older than the history gives the oldest remembered.
        """
        if frame >= self.frame or not self._history:
            return {n: _copy_object(o) for n, o in self.objects.items()}
        frame = max(frame, min(self._history))
        state = self._history.get(frame, {})
        out = {}
        for name, (position, held_by) in state.items():
            source = self.objects.get(name) or self._removed.get(name)
            if source is None:
                continue
            obj = _copy_object(source)
            obj.position, obj.held_by = position.copy(), held_by
            out[name] = obj
        return out

    def remove_object(self, name: str) -> WorldObject:
        """Take an object out of the world (eaten); its past stays in the history."""
        obj = self.objects.pop(name)
        self._removed[name] = obj
        return obj

    def run(
        self,
        duration: float | None = None,
        *,
        until_idle: bool = False,
        tail: float = 1.0,
        max_duration: float = 3600.0,
    ) -> None:
        """Step for ``duration`` seconds, or (``until_idle``) until every actor is idle with nothing queued.

        With ``until_idle``, the world steps ``tail`` seconds more once all are
        idle (so observers see the last movement end), at most ``max_duration``
        seconds in all. Open segments are closed (segmenters flushed) at the end.
        """
        if duration is None and not until_idle:
            raise ValueError("give a duration or until_idle=True")
        for name, value in (("duration", duration), ("tail", tail), ("max_duration", max_duration)):
            if value is not None and not 0 <= value <= MAX_SECONDS:
                raise ValueError(f"{name} must be in [0, {MAX_SECONDS:g}] seconds, not {value!r}")
        limit = min(int(round((duration if duration is not None else max_duration) * self.fps)), MAX_FRAMES)
        if duration is not None and duration * self.fps > MAX_FRAMES:
            raise ValueError(f"{duration:g} s at {self.fps:g} fps is more than {MAX_FRAMES} frames")
        settle = int(round(tail * self.fps))
        quiet = 0
        for _ in range(limit):
            self.step()
            if until_idle and duration is None:
                quiet = quiet + 1 if self.all_idle() else 0
                if quiet > settle:
                    break
        with self._policy():
            for actor in self.actors.values():
                actor._finish()

    def all_idle(self) -> bool:
        return all(a.idle and not a._queue for a in self.actors.values())

    def events_of(self, kind: str, actor: str | None = None) -> list[Event]:
        return [e for e in self.events if e.kind == kind and (actor is None or e.actor == actor)]

    def behaviours(self, actor: str) -> list[Behaviour]:
        return [e.data["behaviour"] for e in self.events_of("behaviour_identified", actor)]
