"""Drives and the should-I trigger on them (Buchsbaum & Blumberg 2005, §6 and §6.2).

Drives (hunger, play...) rise over time and fall when a behaviour satisfies
them; the top-level tuples of the action hierarchy are the motivational
subsystems that satisfy them. A *should-I* trigger fires when the character is
internally motivated: ``drive`` is the drive's level when it exceeds ``above``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from toolkit import ConfigError, Parameter, Trigger, TriggerContext, hookimpl

__all__ = ["Drive", "DriveLevel", "parse_drives"]


@dataclass
class Drive:
    """A drive: its level in [0, 1] and how fast it rises per second."""

    name: str
    level: float
    rate: float

    def rise(self, seconds: float) -> None:
        self.level = min(1.0, self.level + self.rate * seconds)

    def satisfy(self, amount: float) -> None:
        self.level = max(0.0, self.level - amount)


def parse_drives(table: Mapping[str, Any]) -> dict[str, Drive]:
    """``{name: {level, rate}}`` into drives; errors keyed relative to the action table."""
    out = {}
    for name, spec in table.items():
        key = ("drives", name)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="{ level = 0..1, rate = per second }")
        for k in spec:
            if k not in ("level", "rate"):
                raise ConfigError(f"unknown key {k!r}", key=(*key, k), expected="a drive key", available=("level", "rate"))
        level, rate = spec.get("level", 0.0), spec.get("rate", 0.0)
        for k, v in (("level", level), ("rate", rate)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v <= (1 if k == "level" else 10):
                raise ConfigError(f"invalid value {v!r}", key=(*key, k), expected="a number in [0, 1]" if k == "level" else "a rate >= 0 per second")
        out[name] = Drive(name, float(level), float(rate))
    return out


class DriveLevel(Trigger):
    """Should-I: the drive `drive` is above `above`; its value is the drive's level."""

    name = "drive"
    parameters = (
        Parameter("drive", str, doc="The drive's name (hunger, play)."),
        Parameter("above", float, 0.3, "Level above which the character is motivated.", minimum=0.0, maximum=1.0),
    )

    def evaluate(self, context: TriggerContext) -> float:
        level = context.drives.get(self.params["drive"], 0.0)
        return float(level) if level > self.params["above"] else 0.0

    def describe(self) -> str:
        return self.params["drive"]


@hookimpl
def likeme_register_triggers():
    return [DriveLevel]
