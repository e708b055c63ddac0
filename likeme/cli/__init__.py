"""The ``likeme`` command.

One module per command, each adding its parser (``add_parser``) and handling it (``handle(args, pm)``):

============  ==========================  ============================================================
command       module                      what it does
============  ==========================  ============================================================
``demo``      :mod:`likeme.cli.run`       the built-in scenarios, reported
``run``       :mod:`likeme.cli.run`       a scenario file (``--save``, ``--load``, ``--render``)
``plugins``   :mod:`likeme.cli.plugins`   every registered component, with its parameters
``show``      :mod:`likeme.cli.show`      a character, an observer or recordings, as text or a picture
``observe``   :mod:`likeme.cli.observe`   recordings (or frames piped in) watched by an observer
``imitate``   :mod:`likeme.cli.imitate`   a recording performed with the observer's own movements
``validate``  :mod:`likeme.cli.validate`  character, scenario, profile and template files, recordings
``profile``   :mod:`likeme.cli.profile`   a body profile proposed for a recording
============  ==========================  ============================================================

Plugins add more through the ``likeme_register_commands`` hook (``likeme bench``, :mod:`plugins.bench.command`),
with the argument types and checks of :mod:`toolkit.arguments`.

Any error caused by input is printed as one line ``likeme: error: ...`` and the command exits with status 1; no
traceback. The command modules import what a command needs when it runs, so that ``likeme --help`` loads no
library and no plugin that only registers components.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from likeme.cli import imitate, observe, plugins, profile, run, show, validate
from likeme.cli.common import guarded_output
from toolkit import __version__
from toolkit.arguments import CommandParser, check_outputs
from toolkit.errors import LikemeError

if TYPE_CHECKING:  # pragma: no cover
    import argparse

    from toolkit.manager import PluginManager

__all__ = ["main", "build_parser", "COMMANDS"]

COMMANDS = (run, plugins, show, observe, imitate, validate, profile)
"""The command modules, in the order ``likeme --help`` lists their commands."""


def build_parser(pm: PluginManager) -> argparse.ArgumentParser:
    """The ``likeme`` parser: the commands of :data:`COMMANDS`, then those the plugins add."""
    parser = CommandParser(prog="likeme", description="Characters that understand others by simulating them with their "
                           "own bodies.")
    parser.add_argument("--version", action="version", version=f"likeme {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=CommandParser)
    for module in COMMANDS:
        module.add_parser(sub)
    pm.load_command_plugins()  # a lazy manager's plugins that add commands (none to do for a loaded one)
    pm.hook.likeme_register_commands(subparsers=sub)
    return parser


def create_plugin_manager() -> PluginManager:
    """The command's plugin manager: lazy (:func:`toolkit.manager.create_plugin_manager`), so that the parser is
    built with only the plugins that add commands; :func:`main` loads the others when a command runs."""
    from toolkit.manager import create_plugin_manager as create

    return create(lazy=True)


@guarded_output
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``likeme`` command; returns the exit status.

    ``likeme --version`` is answered before anything is loaded; the parser (``--help``) needs only the plugins that
    add commands; every other plugin, and the libraries it imports, is loaded when a command runs.
    """
    if list(sys.argv[1:] if argv is None else argv) == ["--version"]:
        print(f"likeme {__version__}")
        return 0
    try:
        pm = create_plugin_manager()
        parser = build_parser(pm)
        args = parser.parse_args(argv)
        if not getattr(args, "handler", None):
            parser.print_help()
            return 1
        check_outputs(args)
        if getattr(args, "loads_plugins", True):  # a command that loads what it needs itself says so
            pm.load_all()
        return int(args.handler(args, pm) or 0)
    except LikemeError as err:
        print(f"likeme: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("likeme: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (likeme plugins | head): not an error of ours
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
