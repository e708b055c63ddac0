"""Bodies: which parts of a character are tracked, which is the root, which give the facing.

Notation used across likeme (the same in every module):

- ``P``: number of tracked body parts; ``F``: number of frames.
- Positions are metres in a right-handed frame with ``+y`` up. A character's
  *local* frame has its origin on the ground under the root at rest, ``+z``
  pointing where the character faces and ``+x`` to the character's left.
- *Root-relative* coordinates (Buchsbaum & Blumberg 2005, §5.1) are local
  coordinates with the root position subtracted: rotation by the facing and
  translation to the root node.

A :class:`Body` is plain data. It is declared in a character's ``[body]`` table
(see ``docs/character-format.md``) or built in Python.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from toolkit.errors import ConfigError

__all__ = ["Body", "Facing", "Hand"]


@dataclass(frozen=True)
class Facing:
    """The parts that tell which way a body faces (§5.1: the nose against the knees).

    ``left`` and ``right`` define a line across the body (the knees); ``forward``,
    when given, is a part that is always somewhat in front of the body (the nose)
    and resolves which side of that line is the front, as seen from ``behind`` (by
    default the root). A motion-capture skeleton without a nose can use the toes
    seen from the ankle: the foot always points forward, while the toes are
    behind the hips half of every walking step.

    ``also`` gives further left/right pairs across the body (the shoulders beside the hips): the line across is
    then the pairs' across vectors combined, each counting by its length (``plugins/lib/root_frame.py``), so that
    a tracker's jitter turns it less than it turns one short pair. ``left`` and ``right`` are the first pair.
    """

    left: str
    right: str
    forward: str | None = None
    behind: str | None = None
    also: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "also", tuple((str(a), str(b)) for a, b in self.also))

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        """Every (left, right) pair, the first one ``(left, right)``."""
        return ((self.left, self.right), *self.also)

    def table(self) -> dict[str, Any]:
        """The ``[facing]`` table that declares this facing (:meth:`Body.from_config`): ``left`` and ``right`` a
        part each for one pair, lists (one part per pair) for several."""
        if self.also:
            out: dict[str, Any] = {"left": [a for a, _ in self.pairs], "right": [b for _, b in self.pairs]}
        else:
            out = {"left": self.left, "right": self.right}
        if self.forward is not None:
            out["forward"] = self.forward
        if self.behind is not None:
            out["behind"] = self.behind
        return out


@dataclass(frozen=True)
class Hand:
    """A hand whose configuration is the joint angles of its fingers (Kopp & Graeser 2006, §4.1).

    ``wrist`` is the (position) part that carries the hand; ``fingers`` are *angle
    parts*: each one's three values are joint angles in radians, not a position
    (see ``docs/conventions.md``). A finger is seen when its wrist is seen (the
    hand percept "comprises the configurations of the finger joints", §4.1).
    """

    wrist: str
    fingers: tuple[str, ...]


@dataclass(frozen=True)
class Body:
    """The tracked body parts of a character.

    Parameters
    ----------
    parts : sequence of str
        Names of the tracked parts, in the order of the ``P`` axis of every array.
    root : str
        The root node: reference point of root-relative coordinates.
    facing : Facing
        Parts that give the facing direction.
    bones : sequence of (str, str), optional
        Pairs of parts drawn as bones and used for occlusion between parts.
    colours : mapping of str to str, optional
        Colour code of each part (``"#rrggbb"``), used by colour-coded vision and pictures.
    hands : mapping of str to Hand, optional
        Hands by name (``left_hand``...): the angle parts (fingers) each wrist carries.
    """

    parts: tuple[str, ...]
    root: str
    facing: Facing
    bones: tuple[tuple[str, str], ...] = ()
    colours: Mapping[str, str] = field(default_factory=dict)
    hands: Mapping[str, Hand] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "parts", tuple(self.parts))
        object.__setattr__(self, "hands", {n: Hand(h.wrist, tuple(h.fingers)) for n, h in dict(self.hands).items()})
        object.__setattr__(self, "bones", tuple(tuple(b) for b in self.bones))
        object.__setattr__(self, "colours", dict(self.colours))
        if len(set(self.parts)) != len(self.parts):
            dupes = sorted({p for p in self.parts if self.parts.count(p) > 1})
            raise ConfigError(f"duplicate part names {dupes}", key=("parts",), expected="unique names")
        if not self.parts:
            raise ConfigError("a body needs at least one part", key=("parts",), expected="a non-empty list")
        self.index(self.root, key=("root",))
        for i, (left, right) in enumerate(self.facing.pairs):
            at = () if not self.facing.also else (i,)
            self.index(left, key=("facing", "left", *at))
            self.index(right, key=("facing", "right", *at))
            if left == right and i:  # the first pair's is refused where a body is declared (check_body), as before
                raise ConfigError(f"left and right are the same part {left!r}", key=("facing", "right", *at),
                                  expected="two parts across the body", available=[p for p in self.parts if p != left])
        if len(set(self.facing.pairs)) != len(self.facing.pairs):
            raise ConfigError("a left/right pair given twice", key=("facing", "left"),
                              expected="different pairs across the body", available=self.facing.pairs)
        if self.facing.forward is not None:
            self.index(self.facing.forward, key=("facing", "forward"))
        if self.facing.behind is not None:
            self.index(self.facing.behind, key=("facing", "behind"))
            if self.facing.forward is None:
                raise ConfigError("behind without forward", key=("facing", "behind"),
                                  expected="a forward part to be seen from the behind part")
        for i, (a, b) in enumerate(self.bones):
            self.index(a, key=("bones", i))
            self.index(b, key=("bones", i))
        for part in self.colours:
            self.index(part, key=("colours", part))
        seen: dict[str, str] = {}
        for name, hand in self.hands.items():
            self.index(hand.wrist, key=("hands", name, "wrist"))
            if not hand.fingers:
                raise ConfigError("a hand without fingers", key=("hands", name, "fingers"), expected="a non-empty list of parts")
            for finger in hand.fingers:
                self.index(finger, key=("hands", name, "fingers"))
                if finger in seen or finger in (self.root, hand.wrist, *(p for pair in self.facing.pairs for p in pair)):
                    raise ConfigError(f"part {finger!r} cannot be a finger of {name!r}", key=("hands", name, "fingers"),
                                      expected="parts that belong to one hand only and are not the root, facing or wrist parts")
                seen[finger] = name
        for i, (a, b) in enumerate(self.bones):
            if a in seen or b in seen:
                raise ConfigError(f"bone [{a!r}, {b!r}] joins a finger", key=("bones", i),
                                  expected="bones between position parts (fingers are drawn from their joint angles)")

    # -- lookups -----------------------------------------------------------------

    @property
    def n_parts(self) -> int:
        return len(self.parts)

    @property
    def root_index(self) -> int:
        return self.parts.index(self.root)

    @property
    def angle_parts(self) -> tuple[str, ...]:
        """The parts whose values are joint angles (radians), every hand's fingers in order."""
        return tuple(f for hand in self.hands.values() for f in hand.fingers)

    @cached_property
    def angle_mask(self) -> np.ndarray:
        """Boolean (P,): which parts are angle parts (their values are not positions)."""
        angles = set(self.angle_parts)
        return np.array([p in angles for p in self.parts], dtype=bool)

    @cached_property
    def carriers(self) -> np.ndarray:
        """Integer (P,): for a finger the index of its wrist, for a position part its own index."""
        out = np.arange(self.n_parts)
        for hand in self.hands.values():
            for finger in hand.fingers:
                out[self.parts.index(finger)] = self.parts.index(hand.wrist)
        return out

    def index(self, part: str, *, key: Sequence[str | int] = ()) -> int:
        """Index of ``part`` on the ``P`` axis; a :class:`ConfigError` listing the parts if unknown."""
        try:
            return self.parts.index(part)
        except ValueError:
            raise ConfigError(
                f"unknown body part {part!r}", key=key, expected="a part of this body", available=self.parts
            ) from None

    def indices(self, parts: Iterable[str]) -> np.ndarray:
        """Indices of several parts, as an integer array."""
        return np.array([self.index(p) for p in parts], dtype=np.intp)

    def bone_indices(self) -> np.ndarray:
        """Bones as an ``(n_bones, 2)`` integer array."""
        return np.array([[self.index(a), self.index(b)] for a, b in self.bones], dtype=np.intp).reshape(-1, 2)

    # -- declaration -------------------------------------------------------------

    @classmethod
    def from_config(cls, table: Mapping[str, Any]) -> Body:
        """Build a body from a character's ``[body]`` table.

        Raises :class:`ConfigError` with a key path relative to the table.
        """
        known = {"parts", "root", "facing", "bones", "colours", "hands"}
        for key in table:
            if key not in known:
                raise ConfigError(f"unknown key {key!r}", key=(key,), expected="a body key", available=sorted(known))
        parts = table.get("parts")
        if not isinstance(parts, list) or not all(isinstance(p, str) for p in parts):
            raise ConfigError("missing or invalid", key=("parts",), expected="a list of part names")
        root = table.get("root")
        if not isinstance(root, str):
            raise ConfigError("missing or invalid", key=("root",), expected="the name of the root part", available=parts)
        facing = table.get("facing")
        if not isinstance(facing, Mapping):
            raise ConfigError(
                "missing or invalid", key=("facing",), expected='a table {left = "...", right = "...", forward = "..."}'
            )
        for key in facing:
            if key not in ("left", "right", "forward", "behind"):
                raise ConfigError(
                    f"unknown key {key!r}", key=("facing", key), expected="a facing key",
                    available=("behind", "forward", "left", "right")
                )
        lefts, rights = _facing_pairs(facing, parts)
        forward, behind = facing.get("forward"), facing.get("behind")
        for key, value in (("forward", forward), ("behind", behind)):
            if value is not None and not isinstance(value, str):
                raise ConfigError("invalid", key=("facing", key), expected="a part name", available=parts)
        bones = table.get("bones", [])
        if not isinstance(bones, list) or not all(
            isinstance(b, list) and len(b) == 2 and all(isinstance(p, str) for p in b) for b in bones
        ):
            raise ConfigError("invalid", key=("bones",), expected='a list of part pairs like [["root", "head"]]')
        colours = table.get("colours", {})
        if not isinstance(colours, Mapping) or not all(_is_hex_colour(c) for c in colours.values()):
            raise ConfigError("invalid", key=("colours",), expected='a table of part = "#rrggbb"')
        hands = table.get("hands", {})
        if not isinstance(hands, Mapping):
            raise ConfigError("invalid", key=("hands",), expected='a table like { left_hand = { wrist = "left_wrist", '
                              'fingers = ["left_thumb", ...] } }')
        parsed: dict[str, Hand] = {}
        for name, spec in hands.items():
            if not isinstance(spec, Mapping) or set(spec) != {"wrist", "fingers"}:
                raise ConfigError("invalid", key=("hands", name), expected='{ wrist = "PART", fingers = ["PART", ...] }',
                                  available=("fingers", "wrist"))
            fingers = spec["fingers"]
            if not isinstance(spec["wrist"], str) or not isinstance(fingers, list) or not all(isinstance(f, str) for f in fingers):
                raise ConfigError("invalid", key=("hands", name), expected="a wrist part name and a list of finger part names",
                                  available=parts)
            parsed[name] = Hand(spec["wrist"], tuple(fingers))
        return cls(
            parts=tuple(parts),
            root=root,
            facing=Facing(lefts[0], rights[0], forward, behind, tuple(zip(lefts[1:], rights[1:]))),
            bones=tuple((a, b) for a, b in bones),
            colours=dict(colours),
            hands=parsed,
        )


def _facing_pairs(facing: Mapping[str, Any], parts: list[str]) -> tuple[list[str], list[str]]:
    """The ``left`` and ``right`` parts of a ``[facing]`` table, one per pair: a part name each (one pair, the
    paper's knees) or lists of as many part names (several pairs, the first pair first)."""
    given = {key: facing.get(key) for key in ("left", "right")}
    lists = [key for key, value in given.items() if isinstance(value, list)]
    if not lists:
        for key, value in given.items():
            if not isinstance(value, str):
                raise ConfigError("missing or invalid", key=("facing", key),
                                  expected="a part name, or a list of part names (one per left/right pair)",
                                  available=parts)
        return [given["left"]], [given["right"]]
    for key, value in given.items():
        if not isinstance(value, list) or not value or not all(isinstance(p, str) for p in value):
            raise ConfigError("missing" if value is None else "invalid", key=("facing", key),
                              expected="a non-empty list of part names, one per pair, as "
                                       + ("left" if key == "right" else "right") + " is", available=parts)
    if len(given["left"]) != len(given["right"]):
        raise ConfigError(f"{len(given['left'])} left parts and {len(given['right'])} right parts",
                          key=("facing", "right"), expected="one right part for each left part (pairs by position)",
                          available=parts)
    return list(given["left"]), list(given["right"])


def _is_hex_colour(value: object) -> bool:
    if not isinstance(value, str) or len(value) != 7 or value[0] != "#":
        return False
    try:
        int(value[1:], 16)
    except ValueError:
        return False
    return True
