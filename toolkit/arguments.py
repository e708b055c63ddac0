"""Command-line arguments checked where they enter, before any work: what the ``likeme`` command and the plugins that
add commands (``likeme_register_commands``) build their parsers with.

- :class:`CommandParser`: a parser whose errors are one line (``likeme: error: ...``) and exit status 1, like every
  other input error; pass it as ``parser_class`` to ``add_subparsers`` of a command's own sub-commands;
- argument types: :func:`seed_type`, :func:`number_type`, :func:`count_type`, :func:`fps_type` (a bad value is
  refused by argparse with the range it expected);
- output paths: every ``--json``, ``--csv``, ``--plot``, ``--out`` file and ``--render`` or ``DIR`` folder a command
  was given is checked to be writable before it runs (:func:`check_outputs`, called by the command line);
- :func:`observer_options`: the options that change an observer composed from an observer template
  (``--observer``, ``--correspondence``, ``--lengths-for-height``, ``--set``).

Nothing here imports numpy or a plugin: a command's parser is built when ``likeme --help`` runs.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from toolkit.errors import ConfigError

__all__ = ["CommandParser", "seed_type", "number_type", "count_type", "fps_type", "check_output_file",
           "check_output_dir", "check_outputs", "observer_options", "OUTPUT_FILES", "OUTPUT_DIRS"]


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 1, like every other input error."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(1, f"likeme: error: {message} (see '{self.prog} --help')\n")


def seed_type(text: str) -> int:
    """``--seed``: an integer in [0, 2**63 - 1] (numpy's generators take no negative seed)."""
    from toolkit.scenario import MAX_SEED

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"invalid seed {value}: expected an integer in [0, {MAX_SEED}]")
    return value


def number_type(low: float, high: float, what: str = "a number") -> Any:
    """An argument type: a finite number in [low, high] (NaN and infinities refused)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected {what} in [{low:g}, {high:g}]")
        return value

    parse.__name__ = "number"
    return parse


def count_type(low: int, high: int) -> Any:
    """An argument type: an integer in [low, high]."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"invalid value {value}: expected an integer in [{low}, {high}]")
        return value

    parse.__name__ = "count"
    return parse


def fps_type(text: str) -> float:
    """``--fps``: a frame rate in [1/60, :data:`toolkit.recordings.MAX_FPS`] Hz, the range every reader accepts."""
    from toolkit.recordings.recording import FPS_RANGE, MAX_FPS, MIN_FPS

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
    if not (math.isfinite(value) and MIN_FPS <= value <= MAX_FPS):
        raise argparse.ArgumentTypeError(f"invalid frame rate {text!r}: expected frames per second in {FPS_RANGE}")
    return value


OUTPUT_FILES = {"json": "--json", "csv": "--csv", "plot": "--plot", "out": "--out"}
"""Arguments naming a file a command writes, and how they are named in messages (a string value only: ``likeme run
--json`` is a flag and is left alone)."""


OUTPUT_DIRS = {"render": "--render", "dest": "DIR"}
"""Arguments naming a folder a command writes into (created if missing): ``run --render``, ``bench make-data DIR``."""


def _probe(folder: Path, path: Path, option: str, expected: str) -> None:
    """Create and remove a temporary file in ``folder``: the only sure test that the command can write there."""
    from toolkit.files import probe_writable

    try:
        probe_writable(folder)
    except OSError as exc:
        raise ConfigError(f"cannot write there ({exc.strerror or exc})", file=path, key=(option,),
                          expected=expected) from None


def check_output_file(path: str | Path, option: str) -> Path:
    """A file a command will write (``option`` names it in messages, ``--json``): its folder must exist and be
    writable, and it must not be a folder, a device or a FIFO."""
    path = Path(path)
    folder = path.parent
    key = (option,)
    if path.is_dir():
        raise ConfigError("is a folder", file=path, key=key, expected="the path of a file to write")
    if path.exists() and not path.is_file():
        raise ConfigError("not a regular file", file=path, key=key, expected="the path of a file to write")
    if not folder.is_dir():
        raise ConfigError("no such folder", file=folder, key=key, expected="a file in an existing folder")
    _probe(folder, path, option, "a file in a folder this user can write")
    return path


def check_output_dir(path: str | Path, option: str) -> Path:
    """A folder a command will write into (``option`` names it in messages, ``--render``): an existing writable
    folder, or a missing one, created here (with its missing parents)."""
    path = Path(path)
    key = (option,)
    if path.exists() and not path.is_dir():
        raise ConfigError("not a folder", file=path, key=key, expected="a folder to write into (created if missing)")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create the folder ({exc.strerror or exc})", file=path, key=key,
                          expected="a folder to write into (created if missing)") from None
    _probe(path, path, option, "a folder this user can write into")
    return path


def check_outputs(args: argparse.Namespace) -> None:
    """Every output path a command was given (:data:`OUTPUT_FILES`, :data:`OUTPUT_DIRS`), checked before it runs."""
    for name, option in OUTPUT_FILES.items():
        value = getattr(args, name, None)
        if isinstance(value, str):
            check_output_file(value, option)
    for name, option in OUTPUT_DIRS.items():
        value = getattr(args, name, None)
        if isinstance(value, str):
            check_output_dir(value, option)


def observer_options(p: argparse.ArgumentParser) -> None:
    """The options that change the observer composed from the template, shared by ``likeme observe`` and
    ``likeme bench``: ``--observer``, ``--correspondence``, ``--lengths-for-height`` and ``--set``."""
    p.add_argument("--observer", metavar="TEMPLATE", default=None,
                   help="the observer template: a TOML file or the name of one in characters/observers/ (default: "
                   "recordings, for real people; papers: the papers' own comparisons and decisions; "
                   "docs/matchers.md)")
    p.add_argument("--correspondence", metavar="NAME", default="", help="correspondence (default: the observer "
                   "template's; none: the papers' plain observer)")
    p.add_argument("--lengths-for-height", type=number_type(0.0, 1000.0, "metres"), default=None, metavar="M",
                   dest="lengths_for_height",
                   help="the height (m) the length parameters were written for, scaled to the observer's own height "
                   "(default: the observer template's; 0: metres as written, the papers)")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE",
                   help="override a parameter of the observer, e.g. --set matcher.k=4 (repeatable)")
