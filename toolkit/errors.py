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

A message echoes what the user gave (a key, a value, a file name, a CSV header cell), so it is made safe to print
(:func:`printable`): a character a terminal would act on (an escape sequence, a bell, a line break, a right-to-left
override) is shown escaped, ``\x1b`` as the four characters ``\x1b``, so the message stays one line that cannot
retitle or clear the terminal; a part of it longer than :data:`MAX_PART` characters is cut, and a list of available
names longer than :data:`MAX_LISTED` ends with "and N more".
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["LikemeError", "ConfigError", "PluginError", "format_key", "printable", "listed", "MAX_PART",
           "MAX_LISTED"]

MAX_PART = 1000
"""The most characters of one part of a message (the problem, the file, what was expected) before it is cut."""
MAX_LISTED = 60
"""The most names a message lists as available before it says how many more there are."""


def printable(text: object, limit: int = MAX_PART) -> str:
    """``str(text)`` safe for a terminal, on one line: every character that is not printable (controls such as ESC
    and BEL, line and paragraph breaks, bidirectional overrides, lone surrogates) shown as Python writes it escaped
    (``\x1b``, ``\n``, ``\u202e``); cut after ``limit`` characters with how many more there were."""
    text = str(text)
    extra = len(text) - limit
    if extra > 0:
        text = text[:limit]
    if not text.isprintable():
        text = "".join(c if c.isprintable() else c.encode("unicode_escape", "backslashreplace").decode("ascii")
                       for c in text)
    return text + (f"... ({extra:,} more characters)" if extra > 0 else "")


def listed(names: Iterable[object], limit: int = MAX_LISTED) -> str:
    """Names joined with commas, each :func:`printable` (and cut at 100 characters), at most ``limit`` of them and
    then "and N more"."""
    names = list(names)
    shown = ", ".join(printable(n, 100) for n in names[:limit])
    return shown + (f" and {len(names) - limit:,} more" if len(names) > limit else "")


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
        """The one line: ``FILE:LINE:COLUMN: key KEY: PROBLEM; expected EXPECTED; available: NAMES``, every part
        :func:`printable` and bounded."""
        where = ""
        if self.file is not None:
            where = printable(self.file, 300)
            if self.line is not None:
                where += f":{self.line}"
                if self.column is not None:
                    where += f":{self.column}"
        if self.key:
            where += (": " if where else "") + f"key {printable(format_key(self.key), 300)}"
        problem = printable(self.problem)
        text = f"{where}: {problem}" if where else problem
        if self.expected:
            text += f"; expected {printable(self.expected)}"
        if self.available is not None:
            text += f"; available: {listed(self.available) if self.available else '(none)'}"
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
        super().__init__(f"plugin {printable(plugin, 100)!r} failed in {printable(where, 200)}: {printable(problem)}")

    def __reduce__(self) -> tuple:
        """Pickled with its three fields (an error raised in a worker process)."""
        return PluginError, (self.plugin, self.where, self.problem)
