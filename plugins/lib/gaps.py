"""A tracker's short gaps bridged in a motion known whole.

A tracker loses a joint now and then, for a few frames (occluded, out of view, a marker not reconstructed). While
watching, a hidden part is held where it was last seen (docs/conventions.md); a motion read or matched whole knows
where the part was seen again, and :func:`bridged` takes it along a straight line between the two sightings.
"""

from __future__ import annotations

import numpy as np

from toolkit import Motion

__all__ = ["BRIDGE", "bridged"]


BRIDGE = 0.5
"""Seconds: a part hidden for at most this long between two sightings is bridged (:func:`bridged`)."""


def bridged(world: Motion, longest: float = BRIDGE) -> Motion:
    """A motion with each part's short gaps bridged: where a part is hidden for at most ``longest`` seconds between
    two frames it is seen in, it is taken to have moved in a straight line between them, at even speed, and is seen
    there. A part hidden at the start or the end, or for longer, is left hidden (and held, as the rule says).

    The one rule for what is hidden (held where it was last seen, docs/conventions.md) is what a watcher who knows
    only the past can do. A motion known whole, a clip a repertoire is built from or a segment matched once it has
    ended, knows both ends of a tracker's gap: held, the part would stand still and then jump, which every velocity
    taken from it reads as motion (a posegraph's nodes, a command's strokes, the comparison's motion).
    """
    positions = np.asarray(world.positions, dtype=float)
    visible = np.asarray(world.visible, dtype=bool) & np.isfinite(positions).all(axis=-1)
    n = len(positions)
    gap = max(1, int(np.floor(longest * world.fps + 1e-9)))
    if n < 3 or visible.all():
        return world
    out, seen = positions.copy(), visible.copy()
    frames = np.arange(n)
    for part in np.flatnonzero(~visible.all(axis=0) & visible.any(axis=0)):
        at = frames[visible[:, part]]
        before = np.searchsorted(at, frames, side="right") - 1  # the last sighting before each frame
        inside = ~visible[:, part] & (before >= 0) & (before < len(at) - 1)
        if not inside.any():
            continue
        a, b = at[before[inside]], at[before[inside] + 1]
        short = b - a - 1 <= gap
        rows = frames[inside][short]
        a, b = a[short], b[short]
        t = ((rows - a) / (b - a))[:, None]
        out[rows, part] = (1.0 - t) * positions[a, part] + t * positions[b, part]
        seen[rows, part] = True
    return Motion(out, world.fps, world.parts, seen, world.world)
