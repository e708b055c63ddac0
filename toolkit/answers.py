"""A matcher's answer checked where it enters the watching loop: a :class:`~toolkit.components.Match` naming a
movement of the observer's own repertoire or none (unknown), with a finite confidence in [0, 1].

Anything else is a :class:`~toolkit.errors.PluginError` naming the matcher, the method, what it returned and what
was expected, for every watcher alike (:mod:`toolkit.watching`) and for a benchmark that calls a matcher itself.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from toolkit.components import Match
from toolkit.errors import LikemeError, PluginError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.character import Character

__all__ = ["check_match", "shown"]


def check_match(character: Character, match: Any, method: str, known: set[str] | None = None) -> Match:
    """``character``'s matcher's answer from ``method``, checked: a :class:`Match` naming a movement of the
    character's repertoire (its motor system's) or none (unknown), with a finite confidence in [0, 1]; else a
    :class:`PluginError` naming the matcher, the method, what it returned and what was expected. ``known``: names
    found in the repertoire already (a cache the caller keeps)."""
    component = character.matcher
    name = component.name if component is not None else "matcher"
    where = f"{type(component).__name__ if component is not None else 'Matcher'}.{method}"
    known = set() if known is None else known
    if not isinstance(match, Match):
        raise PluginError(name, where, f"returned {shown(match)}, expected a Match or None")
    try:
        confidence = float(match.confidence)
    except (TypeError, ValueError):
        confidence = float("nan")
    if not (np.isfinite(confidence) and 0.0 <= confidence <= 1.0):
        raise PluginError(name, where, f"returned confidence {match.confidence!r} for {match.movement!r}, "
                          f"expected a finite number in [0, 1]")
    movement = match.movement
    if movement is None or movement in known:
        return match
    motor = character.motor
    if not isinstance(movement, str):
        raise PluginError(name, where, f"returned movement {movement!r}, expected a movement name or None")
    if motor is None or _knows(motor, movement):
        known.add(movement)
        return match
    names = list(motor.movements())
    raise PluginError(name, where, f"returned movement {movement!r}, expected a movement of the observer's "
                      f"repertoire or None (unknown); available: {', '.join(map(str, names[:20]))}"
                      + (f" and {len(names) - 20} more" if len(names) > 20 else ""))


def _knows(motor: Any, movement: str) -> bool:
    """Whether ``movement`` is one the motor system can name: one of its ``movements()``, a performable name of one
    (``label``), one it says it ``knows`` (an optional method), else one of the names a motor command graph gives
    what it learns without a label (its ``sequences``, ``together`` movements and ``edge`` names)."""
    known = set(motor.movements())
    if movement in known or motor.label(movement) in known:
        return True
    knows = getattr(motor, "knows", None)
    if callable(knows):
        return bool(knows(movement))
    names = (*getattr(motor, "sequences", {}), *getattr(motor, "together", {}))
    if movement in names:
        return True
    edge = getattr(motor, "edge", None)
    if callable(edge):
        try:
            edge(movement)
            return True
        except (KeyError, LikemeError):
            return False
    return False


def shown(value: Any, limit: int = 120) -> str:
    """``repr(value)``, shortened to ``limit`` characters."""
    try:
        text = repr(value)
    except Exception:  # a plugin's object whose repr fails
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 3] + "..."
