"""Hook specifications: everything a likeme plugin can provide or observe.

A plugin is a module (or object) with functions marked ``@toolkit.hookimpl``
whose names are the hook names below; it is found through the entry-point group
``likeme`` (see ``docs/writing-a-plugin.md``). The built-in plugins in
``plugins/`` are registered through that same group.

Hooks are grouped by the stage of a run that calls them:

1. *registration*: at start-up, each ``likeme_register_*`` hook returns a list
   of component classes. Their ``name`` attribute is what a character's TOML
   file uses to select them; two components of one kind may not share a name.
2. *loading*: while character files are found and composed.
3. *command line*: while the ``likeme`` command builds its parser.
4. *run events*: announced by the runtime while a world steps. They are
   notifications: return values are ignored, and a plugin may keep state of its
   own to extend a run (log, render, change a character's beliefs).

No hook here is ``firstresult``: every implementation is called, through pluggy
(``LIKEME_TRACE_HOOKS=1`` prints every call), and a failing implementation is
named or, in a world that skips failing plugins, dropped
(:meth:`toolkit.manager.PluginManager.failure_policy`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pluggy

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.character import Character
    from toolkit.components import (
        ActionSystem,
        Behaviour,
        Layer,
        Match,
        Matcher,
        MotorSystem,
        MovementRequest,
        Percept,
        Perception,
        Segment,
        Segmenter,
        Correspondence,
        Trigger,
        View,
    )
    from toolkit.runtime import Actor, World

PROJECT = "likeme"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


# ---------------------------------------------------------------------------------
# 1. registration: components selected by name in character files
# ---------------------------------------------------------------------------------


@hookspec
def likeme_register_perceptions() -> list[type[Perception]]:
    """Return perception component classes (``[perception] plugin = NAME``).

    A perception turns the world, seen from an observer, into root-relative
    :class:`~toolkit.components.Percept` s of the target it watches.
    """


@hookspec
def likeme_register_correspondences() -> list[type[Correspondence]]:
    """Return correspondence component classes (``[correspondence] plugin = NAME``).

    A correspondence maps the observed body's poses onto the observer's own (its size, its rest posture) before
    they are segmented and matched: the correspondence problem of Buchsbaum & Blumberg 2005, §7.1 and Kopp &
    Graeser 2006, §6.
    """


@hookspec
def likeme_register_segmenters() -> list[type[Segmenter]]:
    """Return segmenter component classes (``[segmenter] plugin = NAME``).

    A segmenter divides the stream of percepts into segments, streaming (one
    frame at a time) and in batch.
    """


@hookspec
def likeme_register_matchers() -> list[type[Matcher]]:
    """Return matcher component classes (``[matcher] plugin = NAME``).

    A matcher recognises a segment as one of the observer's own movements, at
    the segment's end or, for streaming matchers, as soon as it can commit.
    """


@hookspec
def likeme_register_motor_systems() -> list[type[MotorSystem]]:
    """Return motor system component classes (``[motor] plugin = NAME``).

    A motor system holds a character's own movement repertoire (posegraph,
    motor command graphs, key frames) and produces motions from it.
    """


@hookspec
def likeme_register_action_systems() -> list[type[ActionSystem]]:
    """Return action system component classes (``[action] plugin = NAME``).

    An action system chooses what its character does, interprets recognised
    movements as behaviour and responds (imitates, predicts, helps).
    """


@hookspec
def likeme_register_layers() -> list[type[Layer]]:
    """Return layer component classes (``[layer] plugin = NAME``).

    A layer changes the pose a character shows on top of every movement it performs, frame by frame (a look-at
    turning the head toward the object of attention), without changing the motion its motor system made.
    """


@hookspec
def likeme_register_triggers() -> list[type[Trigger]]:
    """Return trigger component classes, referred to by name inside action systems.

    A trigger is a condition (can-I, should-I, do-until, object selection)
    evaluated to a value in [0, 1].
    """


@hookspec
def likeme_register_views() -> list[type[View]]:
    """Return view component classes (``likeme show --view NAME``, ``likeme run --render``).

    A view draws a character's representations or a running scenario to image
    files, off screen.
    """


# ---------------------------------------------------------------------------------
# 2. loading characters
# ---------------------------------------------------------------------------------


@hookspec
def likeme_character_paths() -> list[Path]:
    """Return folders of character and scenario files this plugin ships.

    They are searched, after the project's own ``characters/`` folder, when a
    file names another by name (``extends = "max"``, ``character = "morris"``).
    """


@hookspec
def likeme_character_composed(character: Character) -> None:
    """Called once a character is composed from its file(s) and its components attached.

    A plugin may inspect it or extend it (wrap a component, add beliefs). Raise
    :class:`~toolkit.errors.ConfigError` to reject it.
    """


# ---------------------------------------------------------------------------------
# 3. command line
# ---------------------------------------------------------------------------------


@hookspec
def likeme_register_commands(subparsers: argparse._SubParsersAction) -> None:
    """Add sub-commands to the ``likeme`` command.

    Call ``subparsers.add_parser(NAME, help=...)`` and ``set_defaults(handler=FUNC)``
    on it; ``FUNC(args, pm)`` is called with the parsed arguments and the plugin
    manager and returns the exit status.

    To build its parser ``likeme`` imports only the plugins that may add commands: those a distribution names in
    the ``likeme.commands`` entry-point group (``NAME = "module"``, NAME as in ``likeme``), or every ``likeme``
    entry of a distribution that names none there. Name yours there, and keep its module light (import what a
    command needs in its handler), so that ``likeme --help`` stays fast; the other plugins are imported when a
    command runs.
    """


# ---------------------------------------------------------------------------------
# 4. run events, in the order a run announces them
# ---------------------------------------------------------------------------------


@hookspec
def likeme_movement_started(world: World, actor: Actor, request: MovementRequest) -> None:
    """``actor`` began performing a movement of its own (chosen, imitating, shrugging): ``request`` says which and why.

    Announced before ``likeme_imitation_started`` when the movement imitates someone.
    """


@hookspec
def likeme_target_perceived(world: World, observer: Actor, target: Actor, percept: Percept) -> None:
    """``observer`` perceived ``target`` this frame (every frame it watches, before segmenting).

    Only announced, not kept in ``world.events``: the observer's working memory (``observer.memory``) keeps
    what it perceived.
    """


@hookspec
def likeme_segment_found(world: World, observer: Actor, target: Actor, segment: Segment) -> None:
    """``observer``'s segmenter closed a segment of what it saw of ``target``.

    Frames of ``segment`` count from when the observer started watching; add
    ``observer.watch_start`` for world frames.
    """


@hookspec
def likeme_movement_recognised(world: World, observer: Actor, target: Actor, segment: Segment | None, match: Match) -> None:
    """``observer``'s matcher answered about a segment (possibly "unknown").

    ``segment`` is ``None`` when a streaming matcher committed before the
    segment ended; ``match.decided_at`` says how far into it.
    """


@hookspec
def likeme_movement_learned(character: Character, movement: str, details: dict[str, Any]) -> None:
    """``character``'s motor system or matcher added a movement (or edge) to its repertoire."""


@hookspec
def likeme_behaviour_identified(world: World, observer: Actor, target: Actor, behaviour: Behaviour) -> None:
    """``observer``'s action system identified (or failed to identify) ``target``'s behaviour."""


@hookspec
def likeme_imitation_started(world: World, actor: Actor, target: Actor, request: MovementRequest) -> None:
    """``actor`` began performing its own movement to imitate ``target``."""


@hookspec
def likeme_imitation_stopped(world: World, actor: Actor, target: Actor, movement: str, reason: str) -> None:
    """``actor`` stopped an imitation: ``reason`` is ``"completed"`` or why it was cut off."""


@hookspec
def likeme_world_stepped(world: World) -> None:
    """The world advanced one frame (``world.frame``, ``world.time``); every actor is placed."""
