"""What several commands share: the view a command draws with, warnings printed on standard error, and the standard
output a command writes to."""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit.errors import ConfigError, LikemeError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["view_of", "warn", "StandardOutput", "guarded_output"]


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
    from toolkit.errors import printable

    for text in warnings:
        print(f"likeme: warning: {printable(source, 300)}: {printable(text)}", file=sys.stderr)
    return len(warnings)


TAKES = "a standard output that takes what is written (not closed, not a full disk or /dev/full)"


class StandardOutput:
    """``sys.stdout`` while a command runs: what cannot be written is one error, or nothing when no one reads.

    - a full or failing target (``> /dev/full``, a full disk): a :class:`ConfigError` naming standard output and the
      reason, raised from the ``print`` that failed (the command stops there, exit status 1); what was buffered is
      dropped, so that the interpreter's last flush does not fail again;
    - a closed standard output (``>&-``: ``sys.stdout`` is ``None``): the same error at the first write (a command
      that prints nothing is not stopped);
    - a reader that went away (``likeme ... | head -n 3``): the rest is dropped and the command goes on, so that the
      files it writes (``--json F``, ``--out``) are still written; its exit status is its own.
    """

    def __init__(self, stream: Any) -> None:
        self._stream = stream
        self.gone = False  # nothing more is written (the reader went away, or writing failed)
        self.failed = False  # writing failed (the error was raised)

    def write(self, text: str) -> int:
        return self._call("write", text) if not self.gone else len(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        if not self.gone and self._stream is not None:  # nothing written, nothing to flush
            self._call("flush")

    def _call(self, method: str, *args: Any) -> Any:
        if self._stream is None:
            self.gone = self.failed = True
            raise ConfigError("cannot write the output (closed)", file="standard output", expected=TAKES)
        try:
            return getattr(self._stream, method)(*args)
        except BrokenPipeError:
            self._drop()
            self.gone = True
            return len(args[0]) if args else None
        except OSError as exc:
            from toolkit.files import write_error

            self._drop()
            self.gone = self.failed = True
            raise write_error(exc, "standard output", expected=TAKES) from None

    def _drop(self) -> None:
        """Point the stream's descriptor at the null device: what it still buffers goes nowhere, without an error."""
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())
        except (OSError, AttributeError, ValueError):  # not a file (a StringIO): nothing buffered by the system
            pass

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def guarded_output(main: Callable[..., int]) -> Callable[..., int]:
    """``main`` with :class:`StandardOutput` in place of ``sys.stdout`` while it runs, flushed before it returns:
    a failure to write standard output is the line ``likeme: error: standard output: cannot write the output
    (REASON)`` and exit status 1 however the command ended (``--help`` too)."""

    @functools.wraps(main)
    def run(argv: Any = None) -> int:
        real = sys.stdout
        guard = StandardOutput(real)
        sys.stdout = guard
        try:
            try:
                status = main(argv)
            except LikemeError as err:  # what main answers before its own handler (--version)
                print(f"likeme: error: {err}", file=sys.stderr)
                return 1
            except SystemExit:  # --help, an argparse error: flushed the same way
                if not _flush(guard):
                    raise SystemExit(1) from None
                raise
            return status if _flush(guard) else 1
        finally:
            if sys.stdout is guard:
                sys.stdout = real

    return run


def _flush(guard: StandardOutput) -> bool:
    """Flush ``guard``; False (the error printed) when standard output could not be written."""
    try:
        guard.flush()
    except LikemeError as err:
        print(f"likeme: error: {err}", file=sys.stderr)
        return False
    return True
