"""The pluggable component kinds and the values that flow between them.

A character's pipeline is six stages, each a component chosen by name in its
TOML file and provided by a plugin (see :mod:`toolkit.hookspecs`):

============  ======================  ===============================================
stage         component kind          turns ...
============  ======================  ===============================================
perceive      :class:`Perception`       the world into a :class:`Percept` of the target
correspond    :class:`Correspondence`   the target's poses into poses of one's own body
segment       :class:`Segmenter`        the stream of poses into :class:`Segment` s
match         :class:`Matcher`          a segment (or its beginning) into a :class:`Match`
interpret     :class:`ActionSystem`     a match into a :class:`Behaviour`
respond       :class:`ActionSystem`     all of it into a :class:`MovementRequest`
============  ======================  ===============================================

and the :class:`MotorSystem` turns a request into a :class:`~toolkit.motion.Motion`
the character performs, over which a :class:`Layer` (a look-at) may change the pose
it shows frame by frame. :class:`Trigger` components are the conditions an action
system evaluates (can-I, should-I, do-until).

Every component is built from validated parameters (its ``parameters`` tuple)
and then attached to the character that owns it, so it can reach the owner's
body and motor system (a segmenter compares with the owner's own hub pose).

What a component can do beyond its kind's minimum is *declared* on its class
(``Perception.watches_recordings``, ``Matcher.streaming``, ``Matcher.motor_systems``)
and checked when it is registered, never found out by comparing its methods with
the base class. The watching loop (:mod:`toolkit.watching`) gives segmenters and
matchers poses in the observer's own parts, with hidden parts held as
``docs/conventions.md`` says; the frame rate reaches every stage through its
``reset`` (``Perception.reset(fps)``, ``Segmenter.reset(parts, fps)``) or, for a
matcher, through the working memory it is given (``memory.fps``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from toolkit.errors import ConfigError
from toolkit.motion import Motion, fill_hidden
from toolkit.params import Parameter, length_names, scaled, validate_params

if TYPE_CHECKING:  # pragma: no cover - imports for annotations only
    from pathlib import Path

    from toolkit.character import Character
    from toolkit.runtime import Actor, World
    from toolkit.watching import WorkingMemory

__all__ = [
    "Component",
    "Perception",
    "Correspondence",
    "Segmenter",
    "Matcher",
    "MotorSystem",
    "ActionSystem",
    "Layer",
    "Trigger",
    "View",
    "KINDS",
    "Percept",
    "Segment",
    "Match",
    "Behaviour",
    "MovementRequest",
    "TriggerContext",
    "provides",
    "protocol_members",
]


# -- values ---------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Percept:
    """What an observer perceived of a target at one instant.

    Attributes
    ----------
    time : float
        World time in seconds.
    pose : array, shape (P, 3)
        Root-relative positions of the target's parts in the target's body frame (§5.1).
    visible : array of bool, shape (P,)
        Which parts were seen; ``pose`` rows of hidden parts are meaningless.
    world : array, shape (P, 3)
        World positions of the seen parts (NaN for hidden ones).
    root : array, shape (3,)
        The target's root in world coordinates as perceived (NaN if not seen).
    heading : float
        The target's perceived heading in radians (NaN if it could not be found).
    objects : mapping of str to array (3,)
        World positions of the objects the observer can see.
    kinds : mapping of str to str
        What each seen object looks like: its kind, as colour-coded vision tells it (B&B §4.2); an object
        seen without one is of an unknown kind.
    sizes : mapping of str to float
        The apparent radius (m) of each seen object.
    """

    time: float
    pose: np.ndarray
    visible: np.ndarray
    world: np.ndarray
    root: np.ndarray
    heading: float
    objects: Mapping[str, np.ndarray] = field(default_factory=dict)
    kinds: Mapping[str, str] = field(default_factory=dict)
    sizes: Mapping[str, float] = field(default_factory=dict)

    def __repr__(self) -> str:
        seen = int(np.count_nonzero(self.visible))
        return (f"Percept(t={self.time:.3f}s, {seen} of {len(self.visible)} parts seen, "
                f"{len(self.objects)} object(s) seen)")


@dataclass(frozen=True)
class Segment:
    """A stretch of the observed stream believed to hold one movement.

    ``start`` is the first frame, ``end`` is one past the last (exclusive), both
    counted from the first frame the segmenter was given.

    Attributes
    ----------
    reason : str
        Why the segment ends where it does, in the segmenter's words ("back at a hub", "a change of direction",
        "the end of the stream"); empty when it does not say. ``likeme observe`` prints it.
    """

    start: int
    end: int
    fps: float
    reason: str = ""

    def __post_init__(self) -> None:
        if not 0 <= self.start < self.end:
            raise ValueError(f"a segment needs 0 <= start < end, got {self.start}..{self.end}")

    @property
    def n_frames(self) -> int:
        return self.end - self.start

    @property
    def start_time(self) -> float:
        return self.start / self.fps

    @property
    def end_time(self) -> float:
        return self.end / self.fps

    @property
    def duration(self) -> float:
        return self.n_frames / self.fps


@dataclass(frozen=True)
class Match:
    """A matcher's answer about one segment.

    The matcher explains its answer in the typed fields below; the watching loop, the runtime and the command line
    read those and nothing else of it (``details`` is the matcher's own, for views, tests and its own reports).

    Attributes
    ----------
    movement : str or None
        The recognised movement of the observer's own repertoire; ``None`` means unknown.
    confidence : float
        In [0, 1].
    decided_at : int or None
        Frames into the segment at which the matcher committed; ``None`` when it
        waited for the segment's end.
    path : tuple
        The matched path through the observer's motor graph, if the matcher has one.
    details : mapping
        Anything else the matcher wants to keep with the answer (its votes, its prediction errors).
    candidates : tuple of (str, float)
        Ranked candidates, best first (B&B Fig. 13): each movement the matcher found near the segment with its
        distance (lower is closer; the matcher's own measure, so only ratios between candidates of one match mean
        anything). Empty when the matcher ranks nothing; when given with a known answer, the first is
        ``movement``; with an unknown one, the movements it considered and rejected, nearest first.
    stop : bool
        After committing (a streaming matcher's early answer), the demonstration deviates from ``movement``: an
        imitation of it is stopped (K&G 2006, Fig. 3, "stop imitation"); ``reason`` says why.
    reason : str
        Why the answer is what it is, in the matcher's words: why a segment is unknown ("too far from every path",
        "nothing visible") or why an imitation stops ("deviation"). Empty when there is nothing to explain.
    nearest : str or None
        With an unknown answer: the movement that came nearest and was rejected (``None``: none came near).
    score : float or None
        The number the answer was decided on, in the matcher's own measure (a distance, a prediction error; lower
        is closer); ``None`` when the matcher decides on none.
    threshold : float or None
        The largest ``score`` the matcher accepts for a known answer: an answer whose score is above it is unknown.
    measure : str
        What ``score`` and ``threshold`` are, for people ("mean pose distance (eq. 3)").
    """

    movement: str | None
    confidence: float = 0.0
    decided_at: int | None = None
    path: tuple = ()
    details: Mapping[str, Any] = field(default_factory=dict)
    candidates: tuple[tuple[str, float], ...] = ()
    stop: bool = False
    reason: str = ""
    nearest: str | None = None
    score: float | None = None
    threshold: float | None = None
    measure: str = ""

    @property
    def known(self) -> bool:
        return self.movement is not None

    @classmethod
    def unknown(cls, reason: str = "", **fields: Any) -> Match:
        """The explicit "nothing fits" answer, with why (``reason``) and any other typed field (``nearest``,
        ``score``, ``threshold``, ``measure``, ``path``, ``details``, ``candidates``)."""
        return cls(None, 0.0, None, reason=reason, **fields)


@dataclass(frozen=True)
class Behaviour:
    """What an observer believes the target is doing and why (Buchsbaum & Blumberg §6).

    ``known`` is false for an explicit "I don't know" (the shrug). ``learned`` holds what the observer learned
    from it: the category each object kind affords (``{"ice_cream": "food"}``, §6.3). ``seen_as``: why each object
    named was taken for what it was (its kind and the look that told it, §4.2); ``in_sight``: the objects in the
    target's line of sight as the observer read it, with how far each lay off the gaze (degrees, §6.1.2). A report
    shows these; ``details`` is the action system's own (the paths it tried, the line of sight).
    """

    known: bool
    movement: str | None = None
    path: tuple[str, ...] = ()
    motivation: tuple[str, ...] = ()
    goal: tuple[str, ...] = ()
    object: str | None = None
    prediction: tuple[str, ...] = ()
    details: Mapping[str, Any] = field(default_factory=dict)
    learned: Mapping[str, str] = field(default_factory=dict)
    seen_as: Mapping[str, str] = field(default_factory=dict)
    in_sight: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class MovementRequest:
    """An action system's request to its own motor system.

    ``imitating`` names the actor being imitated, if this is an imitation. ``response``: what the request answers
    when it is an observer's response to a behaviour it identified (``"imitate"``, ``"shrug"``), for reports;
    empty for a movement chosen on its own.
    """

    movement: str
    speed: float = 1.0
    reason: str = ""
    imitating: str | None = None
    object: str | None = None
    response: str = ""


@dataclass(frozen=True)
class TriggerContext:
    """What a trigger is evaluated against.

    Attributes
    ----------
    actor : Actor
        The character the trigger is evaluated for: the character itself, or the
        target when an observer simulates it (Buchsbaum & Blumberg §6.1).
    world : World or a view of it
        Anything with ``objects`` (name to :class:`~toolkit.runtime.WorldObject`):
        the live world, or the objects as they were when a movement began.
    object : str or None
        The current object of attention.
    beliefs : mapping of str to str
        What the *evaluating* character believes each object type affords
        (``{"cheese": "food"}``); an object type missing here is unknown to it.
    drives : mapping of str to float
        Drive levels in [0, 1] (empty when simulating someone else's motivation).
    params : mapping
        Anything else an action system passes down.
    """

    actor: Actor
    world: Any
    object: str | None = None
    beliefs: Mapping[str, str] = field(default_factory=dict)
    drives: Mapping[str, float] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)

    def attended(self) -> Any:
        """The object of attention as a :class:`~toolkit.runtime.WorldObject`, or ``None``."""
        return self.world.objects.get(self.object) if self.object is not None else None

    def category(self, obj: Any) -> str | None:
        """What the evaluating character believes ``obj`` affords (``None``: unknown)."""
        return self.beliefs.get(obj.kind)


# -- components -----------------------------------------------------------------


class Component(ABC):
    """Base of every pluggable component.

    Subclasses set ``name`` (the name TOML uses) and ``parameters``; the class
    docstring's first line is the summary ``likeme plugins`` prints.
    Parameters are validated on construction and kept in ``self.params``.
    """

    kind: ClassVar[str] = "component"
    name: ClassVar[str] = ""
    parameters: ClassVar[tuple[Parameter, ...]] = ()

    def __init__(self, **params: Any) -> None:
        self.params: Mapping[str, Any] = MappingProxyType(
            validate_params(f"{self.kind} {self.name!r}", self.parameters, params)
        )
        self.declared: Mapping[str, Any] = self.params  # as written, before lengths are scaled to the body
        self.owner: Character | None = None

    @classmethod
    def summary(cls) -> str:
        doc = (cls.__doc__ or "").strip()
        return doc.splitlines()[0] if doc else ""

    def attach(self, owner: Character) -> None:
        """Called once the owning character is composed. Override to read the owner's body or motor system."""
        self.owner = owner

    def scale_lengths(self, factor: float) -> None:
        """Multiply every parameter declared a ``length`` by ``factor`` (the character's own height over the height
        its lengths were meant for). Called by the character before :meth:`attach`; ``declared`` keeps the values
        as written, which every call scales from."""
        self.params = MappingProxyType(scaled(self.declared, length_names(self.parameters), factor))

    def inspect(self) -> Mapping[str, Any]:
        """What the component holds now, read-only, for views and tests (its signals: a segmenter's last
        analysis, a matcher's candidates and prediction errors). Empty by default.

        The one way to look inside a component: views never reach for its attributes or write into it.
        """
        return MappingProxyType({})

    def get_state(self) -> dict[str, Any]:
        """What this component has learned, as JSON-ready data (empty if it learns nothing).

        Saved by :func:`toolkit.state.save_state`; must round-trip through :meth:`set_state`.
        """
        return {}

    def set_state(self, state: dict[str, Any], *, check: bool = False) -> None:
        """Restore what :meth:`get_state` returned (on a freshly composed component).

        Raise :class:`~toolkit.errors.ConfigError` (keys relative to ``state``) for data it cannot use, before
        changing anything: a state file is applied all or nothing. With ``check=True`` only check ``state`` (every
        type, value and name, against the component as it is now) and change nothing: a later ``set_state(state)``
        must then succeed. ``state`` comes from a file that passed the schema of :mod:`toolkit.state` (JSON values,
        bounded depth, integers and strings, finite numbers) but may hold any JSON type anywhere.
        """
        if state:
            raise ConfigError(f"{self.kind} {self.name!r} keeps no state, but the file has some", expected="no state",
                              available=sorted(state))

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items() if not isinstance(v, (dict, list)))
        return f"{type(self).__name__}({args})"


class Perception(Component):
    """Turns what the observer's eye gets of the world into root-relative percepts of a target.

    A perception that can read recorded world positions without a world (a motion-capture file, a tracker)
    declares ``watches_recordings = True`` and implements :meth:`perceive_pose`.
    """

    kind = "perception"
    watches_recordings: ClassVar[bool] = False
    """Whether it perceives recorded poses without a world (:meth:`perceive_pose`): ``likeme observe`` needs one."""

    def reset(self, fps: float) -> None:
        """A new stream of frames at ``fps`` begins (a new target, a new recording): forget buffered state."""

    @abstractmethod
    def perceive(self, observer: Actor, target: Actor, world: World) -> Percept:
        """What ``observer`` perceives of ``target`` now."""

    def perceive_pose(self, positions: np.ndarray, visible: np.ndarray, body: Any, time: float) -> Percept:
        """A percept of a body from recorded world positions (P, 3) alone, without a world: live or recorded input.

        Implemented by perceptions that declare ``watches_recordings``; those that need the world (an eye,
        occluders) do not implement it.
        """
        raise NotImplementedError(f"perception {self.name!r} needs a world; it cannot watch recorded poses")

    def in_view(self, observer: Actor, target: Actor, world: World, points: np.ndarray) -> np.ndarray | None:
        """Whether an object at each of ``points`` (n, 3) would be seen now (in view, not hidden): where an object
        remembered but not seen any more should have been seen, it is gone. ``None``: this perception cannot tell
        (remembered objects are then kept where they were last seen)."""
        return None

    def perceive_poses(self, positions: np.ndarray, visible: np.ndarray | None, body: Any,
                       times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Root-relative poses (n, P, 3) and visibility (n, P) of ``n`` recorded frames of world positions.

        Exactly what ``n`` calls of :meth:`perceive_pose` would give, in order (the default makes those calls);
        a perception that can work on a block of frames at once overrides it for speed.
        """
        percepts = [self.perceive_pose(positions[i], None if visible is None else visible[i], body, float(times[i]))
                    for i in range(len(positions))]
        if not percepts:
            return np.zeros((0, *np.shape(positions)[1:])), np.zeros((0, np.shape(positions)[1]), dtype=bool)
        return np.stack([p.pose for p in percepts]), np.stack([p.visible for p in percepts])


class Correspondence(Component):
    """Maps the observed body onto the observer's own: the correspondence problem (B&B 2005 §7.1, K&G 2006 §6).

    Between perception and the segmenter and matcher: the watching loop gives it the perceived root-relative
    poses in the observer's own parts, hidden parts held (``docs/conventions.md``), and stores what it returns in
    working memory, so that everything downstream compares another body's movement with its own movements.

    Streaming protocol: :meth:`reset` when a new stream (a new demonstrator) begins, then :meth:`map_block` for
    every packet of frames in order. A correspondence estimates what it needs of the demonstrator (their size,
    their rest posture) from the frames seen so far: row ``i`` of a block depends on the rows up to ``i`` only,
    so the result does not depend on how the frames were packed.
    """

    kind = "correspondence"

    @abstractmethod
    def reset(self, parts: Sequence[str], fps: float) -> None:
        """A new stream of poses of ``parts`` (the observer's own) at ``fps``: forget the last demonstrator."""

    @abstractmethod
    def map_block(self, poses: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """``n`` perceived root-relative poses (n, P, 3) with masks (n, P), in arrival order, mapped onto the
        observer's body (n, P, 3). Rows of parts never seen are NaN in and may be NaN out."""


class Segmenter(Component):
    """Divides a stream of observed poses into segments, one frame at a time or in batch.

    Streaming protocol: :meth:`reset`, then :meth:`push` per frame (each call
    returns the segments that closed at that frame), then :meth:`flush` at the
    end of the stream. :attr:`active_since` is the start frame of a segment
    that has begun but not ended. :meth:`segment` runs the protocol over a whole
    motion; subclasses may override it with a vectorised equivalent.

    Poses come in the observer's own parts (``parts`` of :meth:`reset`), hidden
    parts held at their last seen value (``docs/conventions.md``).
    """

    kind = "segmenter"

    none_found: ClassVar[str] = ""
    """What to tell a user whose whole recording gave no segment: how this segmenter begins a movement, and what
    to try where that never happens (``likeme observe`` prints it under such a file); empty: nothing to add."""

    @abstractmethod
    def reset(self, parts: Sequence[str], fps: float) -> None:
        """Start a new stream of poses of ``parts`` at ``fps``; frame numbering restarts at 0."""

    @abstractmethod
    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        """One root-relative pose (P, 3) with its mask (P,); returns segments that ended here."""

    @abstractmethod
    def flush(self) -> list[Segment]:
        """End of stream: close and return a segment still open, if the segmenter accepts it."""

    @property
    @abstractmethod
    def active_since(self) -> int | None:
        """Start frame of the segment under way, or ``None`` between segments."""

    def push_block(self, poses: np.ndarray, visible: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """``n`` poses (n, P, 3) with masks (n, P) pushed one after another.

        Returns the segments that closed, each with the index into the block of the frame whose push closed
        it, and :attr:`active_since` after each frame (n,) (-1: none). Exactly what ``n`` calls of
        :meth:`push` give (the default makes them); a segmenter that can compute its per-frame evidence for a
        block at once overrides it for speed.
        """
        closed: list[tuple[int, Segment]] = []
        since = np.full(len(poses), -1, dtype=int)
        for i in range(len(poses)):
            closed.extend((i, s) for s in self.push(poses[i], visible[i]))
            start = self.active_since
            if start is not None:
                since[i] = start
        return closed, since

    def segment(self, motion: Motion) -> list[Segment]:
        """All segments of a root-relative motion (its hidden parts filled by the convention first)."""
        self.reset(motion.parts, motion.fps)
        positions = fill_hidden(motion.positions, motion.visible)
        found: list[Segment] = []
        for f in range(motion.n_frames):
            found.extend(self.push(positions[f], motion.visible[f]))
        found.extend(self.flush())
        return found


class Matcher(Component):
    """Recognises an observed segment as one of the observer's own movements.

    A batch matcher implements :meth:`match` and answers when a segment has ended. A *streaming* matcher (one
    that can commit before the segment ends: response facilitation, Kopp & Graeser 2006, §4.4) declares
    ``streaming = True`` and implements :meth:`begin` and :meth:`observe`: the watching loop
    (:class:`toolkit.watching.WatchingLoop`) calls ``begin`` when a segment starts, ``observe`` after every
    frame of it, and :meth:`conclude` when it ends. Both read the segment from the
    :class:`~toolkit.watching.WorkingMemory` they are given, in the observer's own parts; a matcher keeps no
    frames of its own.
    """

    kind = "matcher"
    motor_systems: ClassVar[tuple[str, ...]] = ()
    """Names of the motor systems this matcher works with (empty: any); the first is used when one is composed."""
    streaming: ClassVar[bool] = False
    """Whether it can commit before a segment ends; if so it implements :meth:`begin` and :meth:`observe`."""
    report_details: ClassVar[tuple[str, ...]] = ()
    """Keys of its matches' ``details`` a scenario report shows beside the movement, confidence and decision (the
    forward model's speed and deviation, what was learned), in this order (:mod:`toolkit.report`)."""

    @abstractmethod
    def match(self, motion: Motion) -> Match:
        """The movement in a whole root-relative motion segment."""

    def begin(self, memory: WorkingMemory) -> None:
        """A segment has started: ``memory`` is its working memory, holding the frames given so far (it grows,
        one frame before each :meth:`observe`). ``memory.fps`` is the frame rate."""

    def observe(self, memory: WorkingMemory) -> Match | None:
        """One more frame of the ongoing segment is in ``memory`` (the newest is ``memory.positions[-1]``);
        return a match to commit now.

        After committing, a match whose ``stop`` is true tells the runtime that the demonstration deviates from
        the committed movement: an imitation of it is stopped (its ``reason`` says why). After a deviation the
        matcher may commit again (K&G 2006, Fig. 3: back to the last correct node, and predict again).
        """
        return None

    def conclude(self, motion: Motion) -> Match | None:
        """The segment has ended; ``motion`` holds all of it.

        Return the answer, or ``None`` when there is nothing to add to what :meth:`observe` committed to.
        """
        return self.match(motion)

    def settled(self) -> int | None:
        """Optional, for a streaming matcher: after how many frames of the segment it follows nothing more changed
        in its state (``None``: it cannot say, the default). When the segmenter then closes only the first ``m``
        frames of what was followed as a segment (a stroke of a longer movement) and ``m`` is at least this, the
        watching loop concludes the state the matcher has instead of beginning again and feeding it those
        frames; a matcher that answers must leave the same state either way."""
        return None

    def replay(self, memory: WorkingMemory, stop: int) -> list[tuple[int, Match]]:
        """Optional, for a streaming matcher: the rows of ``memory``'s segment not given yet, up to row ``stop``
        (exclusive; rows of working memory, as ``memory.start``), given at once (the watching loop calls it when it
        feeds a segment rows that are all there already: a stroke matched on its own frames, a segment whose onset
        the segmenter reported late). Returns what :meth:`observe` would have returned after each of those rows,
        where it was not ``None``, with the row (the commitment, deviations).

        The default gives them one at a time: ``memory.feed(row + 1)``, then :meth:`observe`. A matcher may do less
        work where it knows nothing can happen; it must return the same answers and leave the same state as the
        default."""
        events = []
        for row in range(memory.start + memory.n, stop):
            memory.feed(row + 1)
            match = self.observe(memory)
            if match is not None:
                events.append((row, match))
        return events


class MotorSystem(Component):
    """Produces a character's own movements (and may learn new ones).

    Motions are in the character's local frame (see :mod:`toolkit.body`): the
    root may move (a jump lifts it), the runtime places the result in the world.
    """

    kind = "motor system"

    @abstractmethod
    def movements(self) -> list[str]:
        """Names of the movements the character can perform."""

    @abstractmethod
    def rest_pose(self) -> np.ndarray:
        """The hub pose the character stands in when idle, local frame, shape (P, 3)."""

    def hub_poses(self) -> np.ndarray:
        """Every hub pose movements start and end in, local frame, shape (H, P, 3); the rest pose first."""
        return np.asarray(self.rest_pose(), dtype=float)[None]

    def label(self, movement: str) -> str:
        """The movement a performable name stands for (several example clips may share one movement)."""
        return movement

    def examples(self, fps: float = 30.0) -> list[tuple[str, Motion]]:
        """(movement, motion) examples of every movement, local frame: the clips the repertoire was built from,
        else one performance of each movement at ``fps``. The templates of matchers that compare examples."""
        return [(m, self.perform(m, fps=fps)) for m in self.movements()]

    @abstractmethod
    def perform(self, movement: str, *, speed: float = 1.0, fps: float = 30.0) -> Motion:
        """The motion of one of :meth:`movements`, sampled at ``fps``, from hub to hub."""

    def reset(self) -> None:
        """Stand at rest again, as at the start: a motor system with a current state (the active node of a motor
        command graph) returns to its hub; one without keeps nothing. Called when an observer starts a new stream
        or clip (:meth:`toolkit.observe.Observer.reset`), so that each is watched from the same state."""

    def interrupt(self, frame: int, pose: np.ndarray, *, fps: float = 30.0) -> Motion | None:
        """The motion last returned by :meth:`perform` was stopped at its ``frame``, the body in ``pose`` (P, 3).

        Return the motion that takes the body from ``pose`` to where the motor system now stands (Kopp &
        Graeser 2006, Fig. 3: "return to last correct motor state node"), or ``None`` to hold ``pose``.
        """
        return None

    def describe(self) -> dict[str, Any]:
        """A summary for reports (counts of movements, nodes, edges...)."""
        return {"movements": len(self.movements())}


class ActionSystem(Component):
    """Chooses what a character does, and interprets and answers what it sees.

    Every method has a neutral default so that a simple action system overrides
    only what it needs.
    """

    kind = "action system"

    def choose(self, actor: Actor, world: World) -> MovementRequest | None:
        """Called when the actor's motor system is idle: what to do next, if anything."""
        return None

    def interpret(self, actor: Actor, target: Actor, segment: Segment, match: Match, world: World) -> Behaviour | None:
        """Identify the behaviour behind a recognised movement (§6.1), or ``None`` if this system does not."""
        return None

    def respond(
        self, actor: Actor, target: Actor, match: Match, behaviour: Behaviour | None, world: World
    ) -> MovementRequest | None:
        """React to a recognised movement (imitate it, help, ignore)."""
        return None

    def performed(self, actor: Actor, request: MovementRequest, world: World) -> None:
        """The actor has started performing ``request`` (to keep correspondence maps)."""

    def completed(self, actor: Actor, request: MovementRequest, world: World) -> None:
        """The actor has finished performing ``request`` (to apply its effect on the world: grasp, eat...)."""

    def describe(self) -> dict[str, Any]:
        return {}

    def render(self) -> str:
        """A text view for people (``likeme show --actions``); by default the :meth:`describe` dict."""
        return "\n".join(f"{k}: {v}" for k, v in self.describe().items()) or f"{self.name} (no state to show)"


class Layer(Component):
    """Changes the pose a character shows on top of every movement it performs (a look-at turning the head).

    The runtime's acting step asks it for each frame of a movement the character performs (not for the way back
    from a stopped imitation, nor for the posture held between movements): :meth:`apply` returns the pose to show
    instead of the motion's, or ``None`` for the motion's own. The motion itself, what the motor system made, is
    never changed, so a layer cannot break a posegraph or a motor command graph; a layer that changes nothing at a
    movement's first and last frames keeps the movement's hub-to-hub continuity.
    """

    kind = "layer"

    @abstractmethod
    def apply(self, actor: Actor, request: MovementRequest, motion: Motion, frame: int,
              world: World) -> np.ndarray | None:
        """The pose (P, 3), in the actor's local frame, it shows at ``frame`` of ``motion``, which performs
        ``request``; ``None``: ``motion.positions[frame]`` as it is."""


class Trigger(Component):
    """A condition an action system evaluates: can-I, should-I, do-until, object selection.

    :meth:`evaluate` returns a value in [0, 1]; 0 means the condition does not hold.
    """

    kind = "trigger"

    @abstractmethod
    def evaluate(self, context: TriggerContext) -> float:
        """The trigger's value for ``context``, in [0, 1]."""

    def describe(self) -> str:
        """A few words for reports ("hunger", "object within reach"); the name by default."""
        return self.name


class View(Component):
    """A picture of one of the toolkit's representations: ``likeme show --view NAME`` or ``likeme run --render``.

    ``subject`` says what it draws: ``"character"`` (a composed
    :class:`~toolkit.character.Character`) or ``"scenario"`` (a
    :class:`~toolkit.scenario.Scenario`, run while it is drawn). Views render
    off screen; the core never imports a drawing library.
    """

    kind = "view"
    subject: ClassVar[str] = "character"

    @abstractmethod
    def draw(self, subject: Any, out: Path) -> list[Path]:
        """Draw ``subject`` to ``out`` (an image file, or a folder for an animation); return the files written."""


def provides(obj: Any, protocol: type, *, needed_by: str, what: str, key: tuple = ("plugin",),
             expected: str | None = None) -> None:
    """Check that ``obj`` (a motor system, say) has every member of ``protocol``, a :class:`typing.Protocol` in which
    a component declares what it needs of another; a :class:`ConfigError` naming what is missing otherwise.

    Called at ``attach``: ``needed_by`` names the component (``"path-search"``), ``what`` the kind of thing it
    needs (``"a posegraph motor system"``), ``expected`` what would do (by default the protocol's members).
    """
    names = protocol_members(protocol)
    missing = [n for n in names if not hasattr(obj, n)]
    if missing:
        raise ConfigError(f"{needed_by} needs {what}, not {getattr(obj, 'name', obj)!r} (it lacks {', '.join(missing)})",
                          key=key, expected=expected or f"one with {', '.join(names)}")


def protocol_members(protocol: type) -> list[str]:
    """The attributes and methods a :class:`typing.Protocol` declares (its own and its bases'), sorted."""
    names: set[str] = set()
    for cls in protocol.__mro__:
        if cls is object or cls.__name__ in ("Protocol", "Generic"):
            continue
        names |= set(getattr(cls, "__annotations__", {}))
        names |= {n for n, v in vars(cls).items() if not n.startswith("_") and (callable(v) or isinstance(v, property))}
    return sorted(names)


KINDS: dict[str, type[Component]] = {
    "perception": Perception,
    "correspondence": Correspondence,
    "segmenter": Segmenter,
    "matcher": Matcher,
    "motor": MotorSystem,
    "action": ActionSystem,
    "layer": Layer,
    "trigger": Trigger,
    "view": View,
}
"""Each component kind by the key it has in a character file and in ``likeme plugins``."""
