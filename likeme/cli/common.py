"""What several commands share: the view a command draws with, and warnings printed on standard error."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit.errors import ConfigError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["view_of", "warn"]


def view_of(pm: PluginManager, name: str, subject: str, settings: list[str]) -> Any:
    """The view ``name`` made with ``--set KEY=VALUE`` settings; it must draw ``subject`` (character or scenario)."""
    from toolkit.config.settings import parse_settings

    cls = pm.registry.get("view", name)
    if cls.subject != subject:
        raise ConfigError(f"view {name!r} draws a {cls.subject}, not a {subject}", key=("--view",),
                          expected=f"a view of {subject}s", available=[n for n in pm.registry.names("view")
                                                                      if pm.registry.get("view", n).subject == subject])
    return cls(**parse_settings(settings, tables=False))


def warn(source: str | Path, warnings: list[str]) -> int:
    """Print each warning as ``likeme: warning: SOURCE: ...`` on standard error; return how many."""
    for text in warnings:
        print(f"likeme: warning: {source}: {text}", file=sys.stderr)
    return len(warnings)
