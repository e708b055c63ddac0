"""Action system ``hierarchical``: a motivational hierarchy of action tuples (Buchsbaum & Blumberg 2005, §6).

Acting: drives rise over time. When the character is idle, the top-level
tuples (one per motivational subsystem) compete; a tuple's value is the product
of its should-I and can-I trigger values, and the winner is drawn with
probability proportional to ``exp(value / temperature)`` among those whose
value is positive (so one tuple is active per level and the character does not
dither). The object selection trigger of the winner picks the object of
attention for everything below it. The same competition repeats in each level's
action group down to a leaf, whose movement is requested from the motor system.
When the movement ends its effect is applied (grasp the object, consume it and
satisfy the drive, toss it).

Do-until contexts control the tuples (§6, §6.2): the active tuples (one per
level, top to leaf) stay active across movements. A leaf is done when its
movement ends: it succeeded if its do-until (success) contexts hold, or (a leaf
without any) if its effect took place. Before every decision the active tuples
are checked from the top: a tuple whose do-until contexts all hold has
succeeded and ends (with everything below it), and so does one whose should-I
triggers no longer hold (its drive is satisfied); a tuple whose other triggers
no longer hold (its object gone, a can-I trigger false) has failed and ends.
The lowest tuple still active then decides its child again: ``get`` (until
holding) reaches again, or jumps, until the object is held; once it is, ``get``
ends and its parent decides again, so ``eat`` follows. A failed child counts
against its parent: after ``retries`` failures in a row the parent gives up on
its object (it is not chosen for that object again), so nothing loops forever;
a tuple none of whose children can run gives up at once. :attr:`log` records
each tuple's beginning and end.

While acting the character keeps two maps (§6.1, §7.4):

- the *movement-action correspondence map*: for each movement, how often each
  path of tuples (top to leaf) was active when it was performed;
- the *transition map*: how often one leaf tuple followed another.

Watching: :meth:`Hierarchical.interpret` identifies the target's behaviour with
the observer's own hierarchy (:mod:`plugins.action.behaviour_identification`), and
:meth:`Hierarchical.respond` imitates the movement or, when the behaviour could
not be identified, shrugs.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any

import numpy as np

from plugins.action.action_tuple import ActionHierarchy, ActionTuple, parse_hierarchy
from plugins.triggers.drives import Drive, parse_drives
from toolkit import ActionSystem, Behaviour, ConfigError, MovementRequest, Parameter, TriggerContext, hookimpl

__all__ = ["Hierarchical", "Active"]

MAX_STEPS = 1000
"""Most tuples one decision may begin or end (a guard: each step ends a tuple or gives one up, so it never binds)."""


@dataclass
class Active:
    """An active action tuple: its name, object of attention, failed children in a row, and (a leaf) its outcome."""

    name: str
    object: str | None
    failures: int = 0
    outcome: bool | None = None


class Hierarchical(ActionSystem):
    """Motivational hierarchy of action tuples with can-I / should-I triggers; identifies others' behaviour (§6)."""

    name = "hierarchical"
    parameters = (
        Parameter("drives", dict, doc="Drives by name: { level = 0..1, rate = rise per second }."),
        Parameter("beliefs", dict, {}, "What each object type affords, as this character believes: { cheese = \"food\" }."),
        Parameter("tuples", dict, doc="Action tuples by name (see plugins/action/action_tuple.py and the character format)."),
        Parameter("experience", dict, {}, "Prior correspondence counts: { MOVEMENT = { \"top > ... > leaf\" = COUNT } }, "
                  "what the character has done before this run."),
        Parameter("temperature", float, 0.1, "Randomness of the competition between tuples (0: always the best).", minimum=0.0),
        Parameter("pause", float, 0.5, "Seconds between the end of one behaviour and the next decision.", minimum=0.0),
        Parameter("identify", bool, True, "Identify the behaviour behind recognised movements of others (§6.1)."),
        Parameter("learn_affordances", bool, True, "Learn what unknown objects afford by watching (§6.3)."),
        Parameter("candidate_margin", float, 0.25, "Fig. 13: a matcher's ranked candidate within (1 + this) times the "
                  "best's distance is close enough for the can-I triggers to choose it instead.", minimum=0.0),
        Parameter("sight_angle", float, 20.0, "Degrees around the target's head-to-nose line (in 3D) beyond which no "
                  "object counts as in its line of sight (§6.1.2); within it, every object within the gaze's "
                  "uncertainty is (plugins/action/line_of_sight.py).", minimum=0.0, maximum=180.0),
        Parameter("gaze", list, ["head", "nose"], "The target's parts whose line gives its line of sight.", items=str),
        Parameter("imitate", bool, False, "Imitate every recognised movement (§5.3); takes precedence over shrugging."),
        Parameter("shrug", str, "", "Movement performed when a behaviour cannot be identified (\"I don't know\"); empty: none."),
        Parameter("seed", int, 0, "Seed of the probabilistic competition."),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        movements = owner.motor.movements()
        self.drives: dict[str, Drive] = parse_drives(self.params["drives"])
        if owner.pm is None:
            raise ConfigError("the hierarchical action system needs a plugin manager for its triggers")
        self.hierarchy: ActionHierarchy = parse_hierarchy(self.params["tuples"], owner.pm.registry, movements, list(self.drives))
        for key, value in self.params["beliefs"].items():
            if not isinstance(value, str):
                raise ConfigError(f"invalid belief {value!r}", key=("beliefs", key), expected="a category name (food, toy)")
        if self.params["shrug"] and self.params["shrug"] not in movements:
            raise ConfigError(f"unknown movement {self.params['shrug']!r}", key=("shrug",), expected="a movement of this character", available=movements)
        self.beliefs: dict[str, str] = dict(self.params["beliefs"])
        self.correspondence: dict[str, Counter[tuple[str, ...]]] = {}
        for movement, counts in self.params["experience"].items():
            if movement not in movements or not isinstance(counts, dict):
                raise ConfigError(f"invalid experience for {movement!r}", key=("experience", movement),
                                  expected="a movement mapped to { \"path > of > tuples\" = count }", available=movements)
            for path_text, n in counts.items():
                path = tuple(p.strip() for p in path_text.split(">"))
                known = path[-1] in self.hierarchy.tuples and path in self.hierarchy.paths_to(path[-1])
                if not known or self.hierarchy.tuples[path[-1]].movement != movement:
                    raise ConfigError(f"not a path of the hierarchy: {path_text!r}", key=("experience", movement, path_text),
                                      expected="top > ... > leaf tuple names joined by '>'")
                if int(n) > 0:  # a count of 0 (an override clearing what a file extended) is no experience
                    self.correspondence.setdefault(movement, Counter())[path] += int(n)
        self.transitions: Counter[tuple[str, str]] = Counter()
        self.history: list[tuple[int, tuple[str, ...], str | None]] = []  # (frame, path, object) of each behaviour begun
        self._rng = np.random.default_rng(self.params["seed"])
        self._stack: list[Active] = []  # the active tuples, top to leaf
        self._given_up: set[tuple[str, str | None]] = set()  # (tuple, object) pairs given up on
        self.log: list[tuple[int, str, str, str | None]] = []  # (frame, began/succeeded/failed/gave up, tuple, object)
        self._frame = 0
        self._current: tuple[tuple[str, ...], str | None] | None = None
        self._last_leaf: str | None = None
        self._last_time: float | None = None
        self._idle_since: float | None = None

    # -- acting --------------------------------------------------------------------------

    def context(self, actor: Any, world: Any, obj: str | None) -> TriggerContext:
        return TriggerContext(actor, world, obj, self.beliefs, {n: d.level for n, d in self.drives.items()})

    def value(self, t: ActionTuple, context: TriggerContext) -> tuple[float, str | None]:
        """A tuple's value (product of its trigger values) and the object of attention it selects.

        An object this tuple has given up on is not selected (its value for that object is 0).
        """
        obj = context.object
        if t.select is not None:
            ignored = {o for n, o in self._given_up if n == t.name}
            if ignored:
                context = TriggerContext(context.actor, context.world, obj, context.beliefs, context.drives,
                                         {**context.params, "ignored": ignored})
            obj = t.select.select(context)
            if obj is None:
                return 0.0, None
            context = TriggerContext(context.actor, context.world, obj, context.beliefs, context.drives, context.params)
        elif (t.name, obj) in self._given_up:
            return 0.0, obj
        v = 1.0
        for trigger in (*t.should, *t.can):
            v *= trigger.evaluate(context)
            if v <= 0:
                return 0.0, obj
        return v, obj

    def _compete(self, names: list[str], context: TriggerContext) -> tuple[str, str | None] | None:
        scored = [(n, *self.value(self.hierarchy.tuples[n], context)) for n in names]
        scored = [(n, v, o) for n, v, o in scored if v > 0]
        if not scored:
            return None
        values = np.array([v for _, v, _ in scored])
        temp = self.params["temperature"]
        if temp <= 0:
            i = int(np.argmax(values))
        else:
            p = np.exp((values - values.max()) / temp)
            i = int(self._rng.choice(len(scored), p=p / p.sum()))
        return scored[i][0], scored[i][2]

    def decide(self, actor: Any, world: Any) -> tuple[tuple[str, ...], str | None] | None:
        """The path of tuples (top to leaf) and object the character would act on now, or ``None``."""
        context = self.context(actor, world, None)
        names, path = self.hierarchy.top, []
        obj = None
        while True:
            won = self._compete(names, context)
            if won is None:
                return None
            name, obj = won
            path.append(name)
            context = TriggerContext(actor, world, obj, context.beliefs, context.drives)
            t = self.hierarchy.tuples[name]
            if t.leaf:
                return tuple(path), obj
            names = t.children

    def choose(self, actor: Any, world: Any) -> MovementRequest | None:
        now = world.time
        if self._last_time is not None:
            for drive in self.drives.values():
                drive.rise(now - self._last_time)
        self._last_time = now
        if self._idle_since is None:
            self._idle_since = now
        if now - self._idle_since < self.params["pause"]:
            return None
        self._frame = world.frame
        self._unwind(actor, world)
        decision = self._descend(actor, world)
        if decision is None:
            return None
        path, obj = decision
        self._current = decision
        self._idle_since = None
        leaf = self.hierarchy.tuples[path[-1]]
        reason = " > ".join(path) + (f" ({obj})" if obj else "")
        return MovementRequest(leaf.movement, reason=reason, object=obj)

    @property
    def active(self) -> tuple[Active, ...]:
        """The active tuples, top to leaf (empty when no behaviour is under way)."""
        return tuple(self._stack)

    def _note_log(self, event: str, entry: Active) -> None:
        self.log.append((self._frame, event, entry.name, entry.object))

    def _end(self, i: int, success: bool) -> None:
        """End the active tuple at level ``i`` (and everything below it); a failure counts against its parent."""
        entry = self._stack[i]
        del self._stack[i:]
        self._note_log("succeeded" if success else "failed", entry)
        if i == 0:
            return
        parent = self._stack[i - 1]
        if success:
            parent.failures = 0
            return
        parent.failures += 1
        if parent.failures > self.hierarchy.tuples[parent.name].retries:
            self._give_up(i - 1)

    def _give_up(self, i: int) -> None:
        """The tuple at level ``i`` gives up on its object: it is not chosen for it again; it ends as a failure."""
        entry = self._stack[i]
        self._given_up.add((entry.name, entry.object))
        self._note_log("gave up", entry)
        self._end(i, False)

    def _unwind(self, actor: Any, world: Any) -> None:
        """End the active tuples whose do-until contexts hold (success) or whose triggers no longer hold (failure)."""
        if self._stack and self.hierarchy.tuples[self._stack[-1].name].leaf:
            leaf = self._stack[-1]
            self._end(len(self._stack) - 1, bool(leaf.outcome))  # a leaf performs once per activation
        for i, entry in enumerate(self._stack):
            t = self.hierarchy.tuples[entry.name]
            context = self.context(actor, world, entry.object)
            if t.until and all(u.evaluate(context) > 0 for u in t.until):
                self._end(i, True)
                return
            if t.should and not all(x.evaluate(context) > 0 for x in t.should):  # motivation satisfied: it is done
                self._end(i, True)
                return
            v, obj = self.value(t, context)
            if v <= 0:
                self._end(i, False)
                return
            if obj != entry.object:  # a new object of attention (the last eaten): what was below was for the old one
                entry.object = obj
                del self._stack[i + 1:]
                return

    def _descend(self, actor: Any, world: Any) -> tuple[tuple[str, ...], str | None] | None:
        """From the lowest active tuple down to a leaf, each level's group competing; ``None`` if nothing can run."""
        for _ in range(MAX_STEPS):
            if not self._stack:
                won = self._compete(self.hierarchy.top, self.context(actor, world, None))
                if won is None:
                    return None
                self._stack.append(Active(*won))
                self._note_log("began", self._stack[-1])
                continue
            entry = self._stack[-1]
            t = self.hierarchy.tuples[entry.name]
            if t.leaf:
                return tuple(e.name for e in self._stack), entry.object
            won = self._compete(t.children, self.context(actor, world, entry.object))
            if won is None:  # none of its children can run for this object
                self._give_up(len(self._stack) - 1)
                continue
            self._stack.append(Active(*won))
            self._note_log("began", self._stack[-1])
        return None

    def performed(self, actor: Any, request: MovementRequest, world: Any) -> None:
        if self._current is None or request.imitating is not None:
            return
        path, _ = self._current
        if self.hierarchy.tuples[path[-1]].movement != request.movement:
            return
        self.correspondence.setdefault(request.movement, Counter())[path] += 1
        self.history.append((world.frame, path, self._current[1]))
        if self._last_leaf is not None:
            self.transitions[(self._last_leaf, path[-1])] += 1
        self._last_leaf = path[-1]

    def completed(self, actor: Any, request: MovementRequest, world: Any) -> None:
        self._idle_since = world.time
        if self._current is None or request.imitating is not None:
            return
        path, obj = self._current
        self._current = None
        leaf = self.hierarchy.tuples[path[-1]]
        if leaf.movement != request.movement:
            return
        target = world.objects.get(obj) if obj else None
        done = leaf.effect == "none"
        if leaf.chance < 1.0 and leaf.effect != "none" and self._rng.random() >= leaf.chance:
            target = None  # the movement missed: no effect this time
        if leaf.effect == "grasp" and target is not None:
            context = self.context(actor, world, obj)
            if all(t.evaluate(context) > 0 for t in leaf.can):  # still within reach when the movement ends
                target.held_by = actor.id
                target.properties["held_in"] = target.properties.get("held_in", "right_hand")
                done = True
        elif leaf.effect == "consume" and target is not None and target.held_by == actor.id:
            world.remove_object(obj)
            self._satisfy(path, leaf)
            done = True
        elif leaf.effect == "toss" and target is not None and target.held_by == actor.id:
            target.held_by = None
            front = actor.world_pose()[actor.body.root_index]
            heading = np.array([np.sin(actor.heading), 0.0, np.cos(actor.heading)])
            target.position = np.array([front[0], target.radius, front[2]]) + 0.35 * heading
            self._satisfy(path, leaf)
            done = True
        if self._stack and self._stack[-1].name == leaf.name:  # its outcome: its success context, else its effect
            if leaf.until:
                context = self.context(actor, world, obj)
                done = all(u.evaluate(context) > 0 for u in leaf.until)
            self._stack[-1].outcome = done

    def _satisfy(self, path: tuple[str, ...], leaf: ActionTuple) -> None:
        drive = self.hierarchy.drive_of(path)
        if drive is not None and leaf.satisfies > 0:
            self.drives[drive].satisfy(leaf.satisfies)

    # -- watching ------------------------------------------------------------------------

    def interpret(self, actor: Any, target: Any, segment: Any, match: Any, world: Any) -> Behaviour | None:
        """Identify the behaviour behind ``match`` from what ``actor`` perceived (its working memory and sightings,
        :mod:`plugins.action.behaviour_identification`); ``world`` is not read. The matcher's close candidates
        (Fig. 13) are told apart by the can-I triggers."""
        if not self.params["identify"] or not match.known:
            return None
        from plugins.action.behaviour_identification import close_candidates, identify

        memory = actor.memory
        if memory is None or memory.n == 0:
            return None
        if segment is not None:
            start, middle, end = segment.start, (segment.start + segment.end) // 2, segment.end - 1
        else:  # committed early: the segment began decided_at rows ago
            start = memory.n - 1 - (match.decided_at or 0)
            middle, end = memory.n - 1 - (match.decided_at or 0) // 2, memory.n - 1
        return identify(self, actor, target, close_candidates(match, self.params["candidate_margin"]), start, middle, end)

    def respond(self, actor: Any, target: Any, match: Any, behaviour: Behaviour | None, world: Any) -> MovementRequest | None:
        """Imitate the movement (if ``imitate``); otherwise shrug at a behaviour it cannot identify (if ``shrug``).

        The request says which (its ``response``: ``"imitate"`` or ``"shrug"``), so that a report says what the
        observer did, not what it would have done.
        """
        if self.params["imitate"] and match.known and match.movement in actor.character.motor.movements():
            return MovementRequest(match.movement, reason=f"imitating {target.id}'s {match.movement}", imitating=target.id,
                                   response="imitate")
        if behaviour is not None and not behaviour.known and self.params["shrug"]:
            return MovementRequest(self.params["shrug"], reason=f"does not know why {target.id} did {match.movement}",
                                   response="shrug")
        return None

    # -- reports ---------------------------------------------------------------------------

    def get_state(self) -> dict[str, Any]:
        """Drives, beliefs, the correspondence and transition maps: everything this character learns by acting and watching."""
        return {
            "drives": {n: d.level for n, d in self.drives.items()},
            "beliefs": dict(self.beliefs),
            "correspondence": {m: {" > ".join(p): n for p, n in c.items()} for m, c in self.correspondence.items()},
            "transitions": [[a, b, n] for (a, b), n in self.transitions.items()],
        }

    def set_state(self, state: dict[str, Any], *, check: bool = False) -> None:
        """Restore drives, beliefs and the two maps; every entry is checked before anything is changed."""
        known = ("drives", "beliefs", "correspondence", "transitions")
        if not isinstance(state, dict):
            raise ConfigError("invalid hierarchical state", expected="a table of " + ", ".join(known))
        for key in state:
            if key not in known:
                raise ConfigError(f"unknown key {key!r}", key=(key,), expected="a hierarchical state key", available=known)

        def table(key: str, what: str) -> dict:
            value = state.get(key, {})
            if not isinstance(value, dict):
                raise ConfigError(f"invalid {key}", key=(key,), expected=what)
            return value

        def count(value: Any, key: tuple) -> int:
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ConfigError(f"invalid count {value!r}", key=key, expected="a whole number >= 0")
            return value

        levels = {}
        for name, level in table("drives", "a table of drive = level").items():
            if name not in self.drives:
                raise ConfigError(f"unknown drive {name!r}", key=("drives", name), expected="a drive of this character", available=list(self.drives))
            if isinstance(level, bool) or not isinstance(level, (int, float)) or not 0 <= level <= 1:
                raise ConfigError(f"invalid level {level!r}", key=("drives", name), expected="a number in [0, 1]")
            levels[name] = float(level)
        beliefs = table("beliefs", "object types mapped to categories")
        if not all(isinstance(v, str) for v in beliefs.values()):
            raise ConfigError("invalid beliefs", key=("beliefs",), expected="object types mapped to categories")
        correspondence: dict[str, Counter] = {}
        for movement, counts in table("correspondence", "a table of movement = {path = count}").items():
            if not isinstance(counts, dict):
                raise ConfigError("invalid correspondence", key=("correspondence", movement),
                                  expected="a table of path = count")
            for text, n in counts.items():
                path = tuple(p.strip() for p in text.split(">"))
                if path[-1] not in self.hierarchy.tuples or path not in self.hierarchy.paths_to(path[-1]):
                    raise ConfigError(f"not a path of the hierarchy: {text!r}", key=("correspondence", movement, text),
                                      expected="top > ... > leaf tuple names")
                correspondence.setdefault(movement, Counter())[path] = count(n, ("correspondence", movement, text))
        transitions: Counter = Counter()
        items = state.get("transitions", [])
        if not isinstance(items, list):
            raise ConfigError("invalid transitions", key=("transitions",),
                              expected="a list of [from_leaf, to_leaf, count]")
        for i, item in enumerate(items):
            if not (isinstance(item, list) and len(item) == 3 and all(isinstance(x, str) and x in self.hierarchy.tuples
                                                                     for x in item[:2])):
                raise ConfigError(f"invalid transition {item!r}", key=("transitions", i), expected="[from_leaf, to_leaf, count]")
            transitions[(item[0], item[1])] = count(item[2], ("transitions", i, 2))
        if check:
            return
        for name, level in levels.items():
            self.drives[name].level = level
        self.beliefs = dict(beliefs)
        self.correspondence = correspondence
        self.transitions = transitions

    def render(self) -> str:
        lines = ["action hierarchy (top level: motivational subsystems; children: the next level's action group):"]
        lines += ["  " + line for line in self.hierarchy.render().splitlines()]
        lines.append("drives: " + ", ".join(f"{n} {d.level:.2f} (+{d.rate:g}/s)" for n, d in self.drives.items()))
        lines.append("beliefs: " + (", ".join(f"{k} is {v}" for k, v in sorted(self.beliefs.items())) or "none"))
        lines.append("movement-action correspondence map:")
        for movement, counts in sorted(self.correspondence.items()):
            paths = ", ".join(f"{' > '.join(p)} x{n}" for p, n in counts.most_common())
            lines.append(f"  {movement}: {paths}")
        if self.transitions:
            lines.append("transition map: " + ", ".join(f"{a} -> {b} x{n}" for (a, b), n in self.transitions.most_common()))
        return "\n".join(lines)

    def describe(self) -> dict[str, Any]:
        return {
            "tuples": len(self.hierarchy.tuples),
            "drives": {n: round(d.level, 3) for n, d in self.drives.items()},
            "beliefs": dict(self.beliefs),
        }


@hookimpl
def likeme_register_action_systems():
    return [Hierarchical]
