"""The name a movement learned by watching is given: ``learned-1``, ``learned-2``...

What a matcher does not recognise it can learn as a new movement of its own (Buchsbaum & Blumberg 2005, §5.2.3: a
movement with no path through the posegraph is added to it; Kopp & Graeser 2006, §4.3: true imitation learning of
what no forward model predicts). Path search and the forward model name it alike, so one character's movements
never collide whichever matcher learned them, whatever was learned, loaded or forgotten before.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["LEARNED", "learned_name"]

LEARNED = "learned"
"""The default prefix of a learned movement's name, before its number."""


def learned_name(known: Iterable[str], prefix: str = LEARNED) -> str:
    """``prefix-N`` for the smallest N >= 1 that no movement in ``known`` is named: a new name, never one of
    ``known`` (``learned-2`` kept when ``learned-1`` was forgotten: the next is ``learned-1``, then ``learned-3``)."""
    taken = set(known)
    number = 1
    while f"{prefix}-{number}" in taken:
        number += 1
    return f"{prefix}-{number}"
