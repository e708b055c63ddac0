"""Declarations read from TOML, bounded: a file's text, its table, and the line a key was written on.

Every character, scenario, observer template and body profile is read here: only a regular UTF-8 file within the
size cap (:mod:`toolkit.files`), arrays and tables nested at most :data:`MAX_DEPTH` deep; a syntax error is a
:class:`~toolkit.errors.ConfigError` with the file, line and column. :func:`find_key_line` finds the line of a key
path, so that an error found later (a value a component refuses) names where it was written.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from toolkit.errors import ConfigError

__all__ = ["MAX_DEPTH", "MAX_DIGITS", "NumberTooLong", "loads", "read_text", "read_toml", "too_deep",
           "find_key_line"]


MAX_DEPTH = 32
"""The deepest nesting of arrays and tables a declaration may have."""


MAX_DIGITS = 4300
"""The most digits an integer may have (Python's own limit on converting text to ``int``)."""

_LONG_INTEGER = re.compile(r"[-+]?[0-9][0-9_]{%d,}" % MAX_DIGITS)


class NumberTooLong(ValueError):
    """An integer of more than :data:`MAX_DIGITS` digits, where it stands in the text."""

    def __init__(self, digits: int, line: int | None, column: int | None) -> None:
        self.digits, self.line, self.column = digits, line, column
        super().__init__(f"an integer of {digits:,} digits")


def loads(text: str) -> dict[str, Any]:
    """:func:`tomllib.loads`, with numbers bounded: an integer of more than :data:`MAX_DIGITS` digits is a
    :class:`NumberTooLong` with its line and column (``tomllib`` raises Python's bare ``ValueError`` for it).
    The one TOML reader of declarations, ``--set`` values and sweep grids; also raises
    :class:`tomllib.TOMLDecodeError` and :class:`RecursionError` as ``tomllib`` does."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        raise
    except ValueError:  # int() past its digit limit: the only ValueError tomllib lets through
        found = _LONG_INTEGER.search(text)
        if found is None:
            raise
        line = text.count("\n", 0, found.start()) + 1
        column = found.start() - (text.rfind("\n", 0, found.start()) + 1) + 1
        digits = sum(c.isdigit() for c in found.group())
        raise NumberTooLong(digits, line, column) from None


def read_text(path: str | Path, what: str, *, kind: str = "config") -> str:
    """A UTF-8 text file's content (a byte-order mark at its start is dropped); a missing, unreadable or not
    regular file (a device, a FIFO, a directory), or one larger than the size cap of ``kind``
    (:data:`toolkit.files.LIMITS`), is a :class:`ConfigError` expecting ``what``."""
    from toolkit.files import open_regular

    path = Path(path)
    if not path.exists() and not path.is_symlink():
        raise ConfigError("file not found", file=path, expected=f"an existing {what}")
    try:
        with open_regular(path, what, kind) as handle:
            return handle.read().decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read file ({exc})", file=path, expected=f"a readable UTF-8 {what}") from None


def read_toml(path: str | Path) -> dict[str, Any]:
    """Parse a TOML file; syntax errors become a :class:`ConfigError` with line and column."""
    path = Path(path)
    text = read_text(path, "TOML file")
    try:
        table = loads(text)
    except RecursionError:
        table = None
    except NumberTooLong as exc:
        return _raise(ConfigError(str(exc), file=path, line=exc.line, column=exc.column,
                                  expected=f"an integer of at most {MAX_DIGITS} digits"))
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        line, col = (int(m.group(1)), int(m.group(2))) if m else (None, None)
        problem = re.sub(r"\s*\(at (line \d+, column \d+|end of document)\)", "", msg)
        return _raise(ConfigError(f"TOML syntax error: {problem}", file=path, line=line, column=col))
    if table is None or too_deep(table):
        return _raise(ConfigError(f"TOML nested more than {MAX_DEPTH} levels deep", file=path,
                                  expected=f"arrays and tables nested at most {MAX_DEPTH} levels deep"))
    return table


def too_deep(table: Mapping[str, Any]) -> bool:
    """Whether arrays and tables nest deeper than :data:`MAX_DEPTH` (walked without recursion)."""
    stack: list[tuple[Any, int]] = [(table, 1)]
    while stack:
        value, depth = stack.pop()
        if depth > MAX_DEPTH:
            return True
        children = value.values() if isinstance(value, Mapping) else value
        stack.extend((v, depth + 1) for v in children if isinstance(v, (Mapping, list)))
    return False


def _raise(err: Exception) -> Any:
    raise err


def find_key_line(path: Path, key: tuple) -> int | None:
    """Best-effort line number of ``key`` in a TOML file: the deepest table header (``[a."b c"]``, ``[[a]]``) or
    ``name =`` line whose key path is a prefix of ``key``. Keys are read by :mod:`tomllib` itself, so quoted keys
    (``[files."*.bvh"]``, ``"left hand" = ...``) and dotted ones are found as TOML reads them."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError:
        return None
    names = [k for k in key if isinstance(k, str)]
    current: list[str] = []
    best: tuple[int, int] | None = None  # (matched depth, line)
    for number, text in enumerate(lines, 1):
        header = _HEADER.match(text)
        found = _header_path(text) if header else _key_path(text)
        if found is None:
            continue
        if header:
            current = found
            full = found
        else:
            full = current + found
        depth = _prefix_depth(full, names)
        if depth == len(full) and (best is None or depth > best[0]):
            best = (depth, number)
    return best[1] if best is not None and best[0] > 0 else None


_HEADER = re.compile(r"^\s*\[")
_KEY_PART = r"""\s*(?:"(?:[^"\\]|\\.)*"|'[^']*'|[A-Za-z0-9_-]+)\s*"""
_KEY = re.compile(r"^(%s(?:\.%s)*)=" % (_KEY_PART, _KEY_PART))


def _walk(table: Any) -> list[str]:
    """The one key path of a table parsed from a single header or ``key = 0`` line."""
    path: list[str] = []
    while True:
        if isinstance(table, list) and table:  # an array of tables: its last one
            table = table[-1]
        if not isinstance(table, dict) or len(table) != 1:
            return path
        name, table = next(iter(table.items()))
        path.append(name)


def _header_path(text: str) -> list[str] | None:
    """The key path of a table header line (``[a.b]``, ``[[a]]``), or ``None`` if it is not one."""
    try:
        return _walk(tomllib.loads(text)) or None
    except tomllib.TOMLDecodeError:
        return None


def _key_path(text: str) -> list[str] | None:
    """The key path of a ``key = value`` line (the value may go on over later lines), or ``None``."""
    m = _KEY.match(text)
    if not m:
        return None
    try:
        return _walk(tomllib.loads(m.group(1) + "= 0")) or None
    except tomllib.TOMLDecodeError:
        return None


def _prefix_depth(path: list[str], key: list[str]) -> int:
    n = 0
    for a, b in zip(path, key):
        if a != b:
            break
        n += 1
    return n
