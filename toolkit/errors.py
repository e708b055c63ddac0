"""The exception types likeme raises on bad input, and how they print.

Every error a user can cause is a :class:`LikemeError`. The command line prints
``str(error)`` on one line and exits with status 1; Python callers catch the
specific subclass.

- :class:`ConfigError`: a character, scenario or profile file is wrong (syntax,
  type, unknown key, unknown plugin name, bad reference). It names the file, the
  key path (or line and column), what was expected and what is available.
- :class:`PluginError`: a plugin could not be loaded, registers something
  invalid, or raised inside a hook or component method. It names the plugin and
  the hook or method.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["LikemeError", "ConfigError", "PluginError", "format_key"]


class LikemeError(Exception):
    """Base class of every error caused by input the user gave."""


def format_key(key: Sequence[str | int]) -> str:
    """Render a key path as TOML would address it: ``motor.movements.jump.keys[2]``."""
    out = ""
    for part in key:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            text = part if _bare(part) else f'"{part}"'
            out += text if not out else f".{text}"
    return out


def _bare(name: str) -> bool:
    return bool(name) and all(c.isalnum() or c in "-_" for c in name)


class ConfigError(LikemeError):
    """A declaration (character, scenario, profile TOML or component parameters) is invalid.

    Parameters
    ----------
    problem : str
        What is wrong, in a few words (``"unknown segmenter 'hub-treshold'"``).
    file : path, optional
        The file the declaration came from.
    key : sequence of str or int, optional
        The key path inside the file, outermost first.
    line, column : int, optional
        Position in the file, when known (syntax errors).
    expected : str, optional
        What would have been accepted.
    available : iterable of str, optional
        The names that exist where a name was looked up (plugins, movements, parts...).
    """

    def __init__(
        self,
        problem: str,
        *,
        file: str | Path | None = None,
        key: Sequence[str | int] = (),
        line: int | None = None,
        column: int | None = None,
        expected: str | None = None,
        available: Iterable[str] | None = None,
    ) -> None:
        self.problem = problem
        self.file = Path(file) if file is not None else None
        self.key = tuple(key)
        self.line = line
        self.column = column
        self.expected = expected
        self.available = None if available is None else tuple(available)
        super().__init__(self.message)

    @property
    def message(self) -> str:
        where = ""
        if self.file is not None:
            where = str(self.file)
            if self.line is not None:
                where += f":{self.line}"
                if self.column is not None:
                    where += f":{self.column}"
        if self.key:
            where += (": " if where else "") + f"key {format_key(self.key)}"
        text = f"{where}: {self.problem}" if where else self.problem
        if self.expected:
            text += f"; expected {self.expected}"
        if self.available is not None:
            listed = ", ".join(self.available) if self.available else "(none)"
            text += f"; available: {listed}"
        return text

    def __reduce__(self) -> tuple:
        """Pickled with every field (an error raised in a worker process of ``--jobs`` or a Dask cluster)."""
        return _config_error, (self.problem, {"file": self.file, "key": self.key, "line": self.line,
                                              "column": self.column, "expected": self.expected,
                                              "available": self.available})

    def within(self, *, file: str | Path | None = None, prefix: Sequence[str | int] = ()) -> ConfigError:
        """The same error placed inside ``file`` under the key path ``prefix``."""
        return ConfigError(
            self.problem,
            file=self.file if self.file is not None else file,
            key=tuple(prefix) + self.key,
            line=self.line,
            column=self.column,
            expected=self.expected,
            available=self.available,
        )


def _config_error(problem: str, fields: dict) -> ConfigError:
    """A :class:`ConfigError` from its pickled fields."""
    return ConfigError(problem, **fields)


class PluginError(LikemeError):
    """A plugin failed: at load time, in what it registered, or inside a hook or method.

    Parameters
    ----------
    plugin : str
        The plugin's registered name (its entry-point name) or a component name.
    where : str
        The hook or method it failed in (``"likeme_register_segmenters"``).
    problem : str
        What went wrong.
    """

    def __init__(self, plugin: str, where: str, problem: str) -> None:
        self.plugin = plugin
        self.where = where
        self.problem = problem
        super().__init__(f"plugin {plugin!r} failed in {where}: {problem}")

    def __reduce__(self) -> tuple:
        """Pickled with its three fields (an error raised in a worker process)."""
        return PluginError, (self.plugin, self.where, self.problem)
