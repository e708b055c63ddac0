"""Objects known by their look: what kind of thing a seen object is, from its colour and its size as seen.

Buchsbaum & Blumberg 2005, §4.2: in colour-coded synthetic vision "each object is assigned a unique color, which can
be used as an identifying tag. By scanning the visual image for pixels of a particular color, the creature can 'see'
an object." An observer knows what the things it knows look like (as Max knows that yellow is the nose, §5): a
*look* is a colour and, optionally, the range of sizes that kind comes in. A seen object is of the kind whose look
is nearest its colour (RGB distance, within the observer's ``tolerance``) and whose size range holds its apparent
radius; an object no known look fits is a thing of its own colour (``"thing #fff0f0"``), a kind the observer may
learn about (§6.3). So a ball painted cheese-yellow is taken for a cheese, and the report says why.

A character file gives the looks in its perception table::

    [perception]
    looks = { cheese = { colour = "#ffd700", radius = [0.02, 0.10] }, ball = { colour = "#ff4040" } }

The world's names and kinds of its objects are never read: only the colour and the size the eye gets.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from toolkit import ConfigError

__all__ = ["Look", "Looks", "SeenKind", "UNKNOWN", "rgb_of"]

UNKNOWN = "thing"
"""The kind-word of an object no known look fits: it is called by its colour, ``"thing #rrggbb"``."""


def rgb_of(colour: str) -> np.ndarray | None:
    """``"#rrggbb"`` as an array (3,) of 0..255; ``None`` if it is not such a colour."""
    if not isinstance(colour, str) or len(colour) != 7 or colour[0] != "#":
        return None
    try:
        return np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    except ValueError:
        return None


def _hex(rgb: np.ndarray) -> str:
    r, g, b = (int(round(float(v))) for v in np.clip(rgb, 0, 255))
    return f"#{r:02x}{g:02x}{b:02x}"


class SeenKind(str):
    """A kind as seen: the kind's name (a ``str``, what beliefs are keyed by) that also carries the evidence it was
    told by: the ``colour`` and apparent ``radius`` seen, and the ``reason`` in words."""

    colour: str
    radius: float
    reason: str

    def __new__(cls, kind: str, colour: str, radius: float, reason: str) -> "SeenKind":
        self = super().__new__(cls, kind)
        self.colour, self.radius, self.reason = colour, float(radius), reason
        return self

    def __reduce__(self) -> tuple:
        return SeenKind, (str(self), self.colour, self.radius, self.reason)


@dataclass(frozen=True)
class Look:
    """What one kind of object looks like: its colour (RGB 0..255) and the apparent radii (m) it comes in."""

    kind: str
    colour: np.ndarray
    radius: tuple[float, float] = (0.0, float("inf"))

    def describe(self) -> str:
        lo, hi = self.radius
        size = "" if (lo, hi) == (0.0, float("inf")) else f", radius {lo:g}-{hi:g} m"
        return f"{self.kind} ({_hex(self.colour)}{size})"


class Looks:
    """The looks an observer knows, and the kind a seen object is of (see the module).

    Parameters
    ----------
    table : mapping
        Kind to ``{ colour = "#rrggbb", radius = [low, high] }`` (radius optional), as a character file gives it.
    tolerance : float
        The largest RGB distance (0..441) at which a colour still is a known look's.
    key : tuple
        Where the table sits in the character file, for errors (``("looks",)``).
    """

    def __init__(self, table: Mapping[str, Any], tolerance: float, key: tuple = ("looks",)) -> None:
        self.tolerance = float(tolerance)
        looks = []
        for kind, spec in table.items():
            where = (*key, kind)
            if not isinstance(spec, Mapping):
                raise ConfigError(f"invalid look {spec!r}", key=where,
                                  expected='{ colour = "#rrggbb", radius = [low, high] } (radius optional)')
            for k in spec:
                if k not in ("colour", "radius"):
                    raise ConfigError(f"unknown key {k!r}", key=(*where, k), expected="a key of a look",
                                      available=["colour", "radius"])
            rgb = rgb_of(spec.get("colour"))
            if rgb is None:
                raise ConfigError(f"invalid colour {spec.get('colour')!r}", key=(*where, "colour"),
                                  expected='a colour "#rrggbb"')
            radius = spec.get("radius", [0.0, float("inf")])
            if (not isinstance(radius, (list, tuple)) or len(radius) != 2
                    or not all(isinstance(r, (int, float)) and not isinstance(r, bool) for r in radius)
                    or not 0 <= radius[0] <= radius[1]):
                raise ConfigError(f"invalid radius {radius!r}", key=(*where, "radius"),
                                  expected="[low, high] in metres, 0 <= low <= high")
            looks.append(Look(str(kind), rgb, (float(radius[0]), float(radius[1]))))
        self.looks = tuple(looks)
        self._colours = np.array([look.colour for look in looks]).reshape(-1, 3)

    def kind(self, colour: np.ndarray | str, radius: float) -> SeenKind:
        """The kind an object of ``colour`` (RGB 0..255, or ``"#rrggbb"``) seen at apparent ``radius`` (m) is of.

        The nearest known look in colour, within ``tolerance``, whose radius range holds ``radius``; else a thing
        called by its colour."""
        rgb = rgb_of(colour) if isinstance(colour, str) else np.asarray(colour, dtype=float)
        if rgb is None:
            raise ValueError(f"not a colour: {colour!r}")
        seen = _hex(rgb)
        if len(self._colours):
            distance = np.linalg.norm(self._colours - rgb, axis=1)
            fits = [(d, i) for i, d in enumerate(distance) if d <= self.tolerance
                    and self.looks[i].radius[0] <= radius <= self.looks[i].radius[1]]
            if fits:
                d, i = min(fits)
                look = self.looks[i]
                return SeenKind(look.kind, seen, radius, f"colour {seen} is {d:.0f} from {look.describe()}, "
                                                         f"apparent radius {radius:.3f} m")
            nearest = int(np.argmin(distance))
            why = (f"colour {seen} is {distance[nearest]:.0f} from the nearest look, "
                   f"{self.looks[nearest].describe()} (tolerance {self.tolerance:g})"
                   if distance[nearest] > self.tolerance else
                   f"colour {seen} is {self.looks[nearest].kind}'s, but an apparent radius of {radius:.3f} m is "
                   f"outside {self.looks[nearest].describe()}")
        else:
            why = "no look is known"
        return SeenKind(f"{UNKNOWN} {seen}", seen, radius, why)
