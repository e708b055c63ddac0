"""The ``likeme bench`` command and its benchmarks: the toolkit's figures, measured (never by timed tests).

``command`` registers the command and its sub-commands; each other module is one benchmark (``watch``,
``behaviour``, ``facilitation``, ``vision``, ``mocap`` for recognition, segmentation and streams of motion-capture
files, ``memory`` for the observer's memory against stream length, ``startup`` for how long the command takes to
start), ``data`` writes and reads the folders the motion-capture benchmarks run on, and ``metrics`` holds the
scores. ``docs/benchmarks.md`` has every table with the command that printed it.

:func:`text_table` lays out the benchmarks' plain-text tables with ``rich``: each column as wide as its widest cell,
two spaces between columns, every line indented, no colour, no markup, no wrapping (a pipe gets the same text as a
terminal).
"""

from __future__ import annotations

import io
from collections.abc import Iterable, Sequence
from typing import Any, TypeVar

T = TypeVar("T")

__all__ = ["text_table", "progress"]


def progress(items: Iterable[T], label: str) -> Iterable[T]:
    """``items`` with a progress bar on standard error (never standard output: a piped table starts with the table),
    cleared when done; the bar is drawn only where standard error is a terminal (elsewhere nothing is written: rich's
    live display would still end with a blank line, issue 37)."""
    import sys

    from rich.console import Console
    from rich.progress import track

    console = Console(stderr=True)
    if not console.is_terminal or sys.stderr is None:
        return items
    return track(items, description=label, transient=True, console=console)


def text_table(rows: Sequence[Sequence[Any]], columns: Sequence[tuple[str, str]], *, header: bool = True,
               indent: int = 2) -> str:
    """``rows`` of cells (each shown as ``str(cell)``) under ``columns`` ``(name, "left" | "right")`` as aligned
    plain text, the names on a first line when ``header``; trailing spaces removed."""
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    table = Table(box=None, show_header=header, header_style="", show_edge=False, pad_edge=False)
    for name, justify in columns:
        table.add_column(Text(name), justify=justify, no_wrap=True)
    for row in rows:
        table.add_row(*(Text(str(cell)) for cell in row))
    out = io.StringIO()
    console = Console(file=out, width=1_000_000, color_system=None, markup=False, emoji=False, highlight=False,
                      soft_wrap=False)
    console.print(table)
    return "\n".join((" " * indent + line).rstrip() for line in out.getvalue().splitlines())
