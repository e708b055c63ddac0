"""The ``likeme`` command.

Sub-commands: ``demo`` (the built-in scenario), ``run SCENARIO``, ``plugins``
(every registered component by kind, with its distribution) and ``validate
FILE...``; plugins add more through the ``likeme_register_commands`` hook.

Any error caused by input is printed as one line ``likeme: error: ...`` and the
command exits with status 1; no traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit import __version__
from toolkit.errors import ConfigError, LikemeError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["main", "build_parser"]


DEMO_SCENARIOS = ("demo", "ice_cream", "imitation_games", "hand_games", "hand_arm_games")
"""What ``likeme demo`` runs: Max imitating Morris's random movements, Max working out why Morris eats,
Max learning Moritz's arm movements in three imitation games and his finger movements in three more, and
following Moritz's wrist and hand at once in the hand-arm games."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 1, like every other input error."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(1, f"likeme: error: {message} (see '{self.prog} --help')\n")


# -- argument types and output paths: checked where they enter, before any work ------------------------


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
    """``--fps``: a frame rate in (0, :data:`toolkit.positions.MAX_FPS`] Hz, the range every reader accepts."""
    from toolkit.positions import MAX_FPS

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid number: {text!r}") from None
    if not (math.isfinite(value) and 0.0 < value <= MAX_FPS):
        raise argparse.ArgumentTypeError(f"invalid frame rate {text!r}: expected frames per second in "
                                         f"(0, {MAX_FPS:g}]")
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


def build_parser(pm: PluginManager) -> argparse.ArgumentParser:
    parser = _Parser(prog="likeme", description="Characters that understand others by simulating them with their own bodies.")
    parser.add_argument("--version", action="version", version=f"likeme {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("demo", help="run the built-in scenario and report what each character did and saw")
    p.add_argument("--seed", type=seed_type, default=None, help="seed for random choices (default: the scenario's)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--keep-going", action="store_true", help="go on without a plugin that fails (default: stop)")
    p.add_argument("--scenario", action="append", metavar="NAME",
                   help=f"built-in scenario to run, repeatable (default: {' and '.join(DEMO_SCENARIOS)})")
    p.set_defaults(handler=cmd_demo)

    p = sub.add_parser("run", help="run a scenario file")
    p.add_argument("scenario", help="scenario TOML file, or the name of a built-in scenario")
    p.add_argument("--seed", type=seed_type, default=None, help="seed for random choices (default: the scenario's)")
    p.add_argument("--duration", type=number_type(0.0, 3600.0, "seconds"), default=None,
                   help="seconds to run, at most 3600 (default: the scenario's)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--keep-going", action="store_true", help="go on without a plugin that fails (default: stop)")
    p.add_argument("--load", metavar="STATE", help="restore what the characters learned from a state file first")
    p.add_argument("--save", metavar="STATE", help="save what the characters learn to a state file (atomically, "
                   "whenever something is learned and at the end)")
    p.add_argument("--render", metavar="DIR", help="draw the run into DIR (PNG frames, GIF and MP4 by default)")
    p.add_argument("--view", default="scenario", metavar="NAME", help="the view that draws it (default: scenario)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a parameter of the view, e.g. --set every=2 --set 'formats=[\"gif\"]' (repeatable)")
    p.set_defaults(handler=cmd_run)

    p = sub.add_parser("plugins", help="list every registered component by kind, with its distribution")
    p.add_argument("--params", action="store_true", help="also list each component's parameters")
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.add_argument("--markdown", action="store_true", help="print a Markdown reference of every component and its parameters")
    p.set_defaults(handler=cmd_plugins)

    p = sub.add_parser("show", help="show a character's representations, or your own recordings, as text or drawn by a "
                       "view to PNG")
    p.add_argument("character", nargs="+", metavar="CHARACTER|FILE",
                   help="character TOML file or name (with --after: the id of an actor of the scenario); with --body: "
                   "the recordings to draw (.bvh and the other formats body profiles read), after an optional "
                   "observer template (default observers/recordings)")
    p.add_argument("--after", metavar="SCENARIO", help="run this scenario first and show the actor as it is then "
                   "(what it learned included)")
    p.add_argument("--actions", action="store_true", help="print the action system (hierarchy, drives, beliefs, maps) as text")
    p.add_argument("--view", metavar="NAME", help="draw the character with this view (see 'likeme plugins'), "
                   "e.g. body, posegraph, motor-command-graph; of recordings: body, hub-signal, speed-profile, "
                   "prediction-error")
    p.add_argument("--out", metavar="FILE.png|DIR", dest="out_path",
                   help="where the view writes its picture: a .png file, or a folder (created if missing) for "
                   "NAME-VIEW.png files (default: NAME-VIEW.png here; NAME: the character's, or each recording's)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a parameter of the view, e.g. --set keys=4 (repeatable)")
    p.add_argument("--body", metavar="PROFILE", help="the body profile of the recordings: with FILEs, draw them as "
                   "the observer composed from the template watches them; without, with --repertoire: show that "
                   "observer, as likeme observe composes it")
    p.add_argument("--repertoire", metavar="DIR", help="with --body: the observer's labelled clips (default with "
                   "FILEs: the recordings themselves, a movement each, and no matcher unless the view needs one)")
    p.add_argument("--segmenter", metavar="NAME", help="with --body: the observer's segmenter (default: the one the "
                   "view needs, else the template's)")
    p.add_argument("--matcher", metavar="NAME", help="with --body: the observer's matcher (default: the one the view "
                   "needs, else the template's)")
    p.add_argument("--correspondence", metavar="NAME", help="with --body: the observer's correspondence (default: "
                   "the template's)")
    p.set_defaults(handler=cmd_show)

    p = sub.add_parser("observe", help="watch recordings (BVH, CSV joint positions, .npy arrays, or '-': frames "
                       "piped in): segments, recognised movements, decisions")
    p.add_argument("files", nargs="+", metavar="FILE", help="recordings (.bvh, .csv, .npy; see docs/formats.md), or "
                   "'-' alone: CSV or JSON lines on standard input, each observation printed as its segment closes")
    p.add_argument("--body", required=True, metavar="PROFILE", help="body profile TOML of the files")
    p.add_argument("--repertoire", required=True, metavar="DIR", help="labelled clips: one folder per movement")
    p.add_argument("--fps", type=fps_type, default=None, metavar="HZ",
                   help="frame rate of recordings without one of their own (a CSV without a time column, a .npy "
                   "array, standard input), the files watched and the repertoire's clips alike; wins over the "
                   "profile's fps; a BVH's Frame Time and a CSV's time column win over it")
    p.add_argument("--segmenter", metavar="NAME", help="segmenter (default: the observer template's, "
                   "characters/observers/recordings.toml)")
    p.add_argument("--matcher", metavar="NAME", help="matcher (default: the observer template's)")
    observer_options(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(handler=cmd_observe)

    p = sub.add_parser("validate", help="check character, scenario and body-profile files and recordings")
    p.add_argument("files", nargs="+", metavar="FILE", help="character, scenario or profile TOML files, or "
                   "recordings (.bvh, .csv, .npy)")
    p.add_argument("--body", metavar="PROFILE", help="also check that each recording has the joints this profile "
                   "maps (and read a .npy array with its joint names), and warn where the profile is probably wrong "
                   "for it (units, up axis, facing)")
    p.add_argument("--strict", action="store_true", help="exit with status 1 on a warning too")
    p.add_argument("--fps", type=fps_type, default=None, metavar="HZ",
                   help="frame rate of recordings without one of their own (as for observe)")
    p.set_defaults(handler=cmd_validate)

    p = sub.add_parser("profile", help="propose a body profile for a recording (BVH, or CSV joint positions)")
    p.add_argument("file", metavar="FILE", help="a BVH file, or a CSV of joint positions (JOINT_x, JOINT_y, JOINT_z)")
    p.add_argument("--out", metavar="PROFILE.toml", help="write the profile there (default: print it)")
    p.set_defaults(handler=cmd_profile)

    pm.load_command_plugins()  # a lazy manager's plugins that add commands (none to do for a loaded one)
    pm.hook.likeme_register_commands(subparsers=sub)
    return parser


def create_plugin_manager() -> PluginManager:
    """The command's plugin manager: lazy (:func:`toolkit.manager.create_plugin_manager`), so that the parser is
    built with only the plugins that add commands; :func:`main` loads the others when a command runs."""
    from toolkit.manager import create_plugin_manager as create

    return create(lazy=True)


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


# -- commands ----------------------------------------------------------------------------


def _view(pm: PluginManager, name: str, subject: str, settings: list[str]) -> Any:
    """The view ``name`` made with ``--set KEY=VALUE`` settings; it must draw ``subject`` (character or scenario)."""
    from toolkit.params import parse_settings

    cls = pm.registry.get("view", name)
    if cls.subject != subject:
        raise ConfigError(f"view {name!r} draws a {cls.subject}, not a {subject}", key=("--view",),
                          expected=f"a view of {subject}s", available=[n for n in pm.registry.names("view")
                                                                      if pm.registry.get("view", n).subject == subject])
    return cls(**parse_settings(settings, tables=False))


def _run_scenario(path: str, pm: PluginManager, args: argparse.Namespace) -> dict[str, Any]:
    from toolkit.report import summarise
    from toolkit.scenario import load_scenario
    from toolkit.state import Checkpoint, StateFile, apply_state, read_state

    if getattr(args, "set", None) and not getattr(args, "render", None):  # a view's settings, and no view
        raise ConfigError("--set without --render", key=("--set",),
                          expected="--render DIR with the settings of the view that draws the run")
    # the --save target and the --load file are checked before any work (the target first: its version is the one
    # this run may overwrite); the loaded state is applied, all or nothing, once the world is composed
    target = StateFile(args.save, loaded=getattr(args, "load", None)) if getattr(args, "save", None) else None
    loaded = read_state(args.load) if getattr(args, "load", None) else None
    scenario = load_scenario(path, pm, seed=args.seed, on_plugin_error="skip" if args.keep_going else "stop")
    if getattr(args, "duration", None) is not None:
        from toolkit.scenario import check_duration

        scenario.duration = check_duration(args.duration, scenario.world.fps, ("--duration",))
    if loaded is not None:
        apply_state(scenario.world, loaded, args.load)
    checkpoint = None
    if target is not None:
        checkpoint = Checkpoint(scenario.world, target)
        pm.register(checkpoint, name="checkpoint")
    view = _view(pm, args.view, "scenario", args.set) if getattr(args, "render", None) else None
    files = []
    try:
        if view is not None:  # a scenario view runs the scenario while it records it, then draws it
            files = view.draw(scenario, Path(args.render))
        else:
            scenario.run()
    finally:
        if checkpoint is not None:
            pm.unregister(checkpoint)
    world = scenario.world
    if checkpoint is not None:
        checkpoint.finish()  # ConfigError if the last save fails or had to go to a conflict file
    if view is not None:
        print(f"wrote {len(files)} file(s) to {args.render}: " + ", ".join(
            sorted({f.suffix.lstrip('.') for f in files})), file=sys.stderr)
    summary = summarise(world, name=scenario.name)
    summary["seed"] = scenario.seed
    summary["description"] = scenario.description.strip()
    return summary


def _print(summaries: list[dict[str, Any]], as_json: bool) -> None:
    from toolkit.report import render_text

    if as_json:
        print(json.dumps(summaries[0] if len(summaries) == 1 else summaries, indent=2))
        return
    for i, summary in enumerate(summaries):
        if i:
            print("\n" + "=" * 100 + "\n")
        if summary["description"]:
            print(summary["description"])
            print()
        print(render_text(summary))


def cmd_demo(args: argparse.Namespace, pm: PluginManager) -> int:
    """Run the built-in scenarios (:data:`DEMO_SCENARIOS` unless ``--scenario`` names others)."""
    _print([_run_scenario(name, pm, args) for name in (args.scenario or DEMO_SCENARIOS)], args.json)
    return 0


def cmd_run(args: argparse.Namespace, pm: PluginManager) -> int:
    _print([_run_scenario(args.scenario, pm, args)], args.json)
    return 0


def plugins_table(pm: PluginManager, *, params: bool = False) -> dict[str, Any]:
    """Every registered component by kind, and every loaded plugin with its hooks."""
    from toolkit.components import KINDS

    registry = pm.registry
    components: dict[str, list[dict[str, Any]]] = {}
    for kind in KINDS:
        rows = []
        for info in registry.infos(kind):
            row: dict[str, Any] = {
                "name": info.name,
                "summary": info.cls.summary(),
                "plugin": info.plugin.name,
                "distribution": info.plugin.distribution,
                "version": info.plugin.version,
            }
            if params:
                row["parameters"] = _parameter_rows(info.cls.parameters)
            rows.append(row)
        components[kind] = rows
    plugins = []
    for name, plugin in pm.list_name_plugin():
        info = pm.plugin_infos.get(name)
        hooks = sorted(h.name for h in (pm.get_hookcallers(plugin) or []))
        plugins.append(
            {
                "name": name,
                "module": info.module if info else repr(plugin),
                "distribution": info.distribution if info else "(registered in Python)",
                "version": info.version if info else "",
                "hooks": hooks,
            }
        )
    skipped = [{"name": i.name, "distribution": i.distribution} for i in pm.skipped]
    failed = [{"name": i.name, "module": i.module, "distribution": i.distribution, "version": i.version,
               "error": str(e)} for i, e in pm.failed]
    return {"components": components, "plugins": plugins, "skipped": skipped, "failed": failed}


def _parameter_rows(parameters: Sequence[Any]) -> list[dict[str, Any]]:
    """Each parameter's name, type and default, and what it does; a table's parameters nested in its row."""
    rows = []
    for p in parameters:
        row: dict[str, Any] = {"name": p.name, "type": p.describe(), "doc": p.doc}
        if p.table:
            row["parameters"] = _parameter_rows(p.parameters)
        rows.append(row)
    return rows


def _print_parameters(rows: list[dict[str, Any]], indent: str = "      ") -> None:
    """``likeme plugins --params``: one line per parameter, a table's parameters indented under it."""
    for p in rows:
        print(f"{indent}{p['name']}: {p['type']}. {p['doc']}")
        _print_parameters(p.get("parameters", []), indent + "    ")


def components_markdown(pm: PluginManager) -> str:
    """Every registered component with its summary and parameter table, as Markdown (``docs/components.md``); a
    table's parameters are rows of their own, keyed ``TABLE.KEY``."""
    from toolkit.components import KINDS
    from toolkit.params import flat_parameters

    lines = [
        "# Component reference",
        "",
        "Generated by `likeme plugins --markdown` from the registered components (built-ins only when",
        "`LIKEME_DISABLE_PLUGIN_AUTOLOAD=1`); a test keeps this file equal to that output.",
        "",
    ]
    for kind in KINDS:
        for info in pm.registry.infos(kind):
            cls = info.cls
            lines += [f"## {KINDS[kind].kind} `{info.name}`", "", f"{cls.summary()} ({info.plugin.module})", ""]
            if not cls.parameters:
                lines += ["No parameters.", ""]
                continue
            lines += ["| key | type and default | effect |", "| --- | --- | --- |"]
            lines += [f"| `{'.'.join(key)}` | {p.describe()} | {p.doc} |" for key, p in flat_parameters(cls.parameters)]
            lines.append("")
    return "\n".join(lines)


def cmd_plugins(args: argparse.Namespace, pm: PluginManager) -> int:
    from toolkit.components import KINDS

    if args.markdown:
        print(components_markdown(pm), end="")
        return 0
    table = plugins_table(pm, params=args.params)
    if args.json:
        print(json.dumps(table, indent=2))
        return 0
    for kind, rows in table["components"].items():
        label = KINDS[kind].kind
        print(f"{label}s ([{kind}] plugin = NAME):" if kind != "trigger" else "triggers:")
        if not rows:
            print("  (none registered)")
        width = max((len(r["name"]) for r in rows), default=0)
        for r in rows:
            dist = f"{r['distribution']} {r['version']}".strip()
            print(f"  {r['name']:<{width}}  {r['summary']}  [{dist}: {r['plugin']}]")
            _print_parameters(r.get("parameters", []))
        print()
    print("plugins:")
    for p in table["plugins"]:
        dist = f"{p['distribution']} {p['version']}".strip()
        print(f"  {p['name']} ({p['module']}, {dist}): {', '.join(p['hooks'])}")
    for s in table["skipped"]:
        print(f"  {s['name']} ({s['distribution']}): skipped, LIKEME_DISABLE_PLUGIN_AUTOLOAD is set")
    for f in table["failed"]:
        print(f"  {f['name']} ({f['module']}, {f['distribution']} {f['version']}): failed to load, left out: "
              f"{f['error']}")
    return 0


RECORDING_SUFFIXES = (".bvh", ".csv", ".npy", ".c3d")
"""File names that ``likeme show --body PROFILE FILE ...`` takes for recordings, not for a character or template."""


def cmd_show(args: argparse.Namespace, pm: PluginManager) -> int:
    from toolkit.character import load_character
    from toolkit.report import describe_character

    for option, value in (("--set", args.set), ("--out", args.out_path)):
        if value and not args.view:  # a view's settings and picture: nothing to apply them to
            raise ConfigError(f"{option} without --view", key=(option,),
                              expected="--view NAME with the view's settings and where it writes its picture")
    files = [f for f in args.character if Path(f).suffix.lower() in RECORDING_SUFFIXES]
    names = [f for f in args.character if f not in files]
    if len(names) > 1 or (files and args.after) or (files and not args.body):
        raise ConfigError(f"cannot show {' and '.join(names) if len(names) > 1 else ' '.join(args.character)}",
                          key=("character",), expected="one character (or observer template), or with --body PROFILE "
                          f"recordings ({', '.join(RECORDING_SUFFIXES)}) after an optional observer template")
    if files:
        return _show_recordings(args, pm, names[0] if names else None, files)
    args.character = names[0]
    if args.after:
        from toolkit.scenario import load_scenario

        world = load_scenario(args.after, pm).run()
        if args.character not in world.actors:
            raise ConfigError(f"no actor {args.character!r} in scenario {args.after!r}", key=("character",),
                              expected="the id of an actor of the scenario", available=list(world.actors))
        character = world.actors[args.character].character
    elif args.body or args.repertoire:
        from toolkit.observe import compose_observer
        from toolkit.profile import load_profile

        if not (args.body and args.repertoire):
            raise ConfigError("--body and --repertoire go together", key=("--repertoire" if args.body else "--body",),
                              expected="both: the recordings' body profile and the observer's labelled clips "
                              "(or --body with recordings to draw)")
        character = compose_observer(pm, load_profile(args.body), args.repertoire, template=args.character,
                                     segmenter=args.segmenter, matcher=args.matcher or "",
                                     correspondence=args.correspondence or "")
    else:
        character = load_character(args.character, pm)
    if args.view:
        view = _view(pm, args.view, "character", args.set)
        name = re.sub(r"[^a-z0-9]+", "-", character.name.lower()).strip("-")
        for path in view.draw(character, _show_out(args.out_path, name, args.view)):
            print(f"wrote {path}")
        return 0
    if args.actions:
        if character.action is None:
            print(f"{character.name} has no action system")
            return 0
        print(f"{character.name}: action system {character.action.name}")
        print(character.action.render())
        return 0
    print(json.dumps(describe_character(character), indent=2))
    return 0


def _show_out(out: str | None, name: str, view: str, several: bool = False) -> Path:
    """Where ``likeme show`` writes the picture of ``name``: ``--out`` when it names a .png file, else NAME-VIEW.png
    in the folder ``--out`` names (created if missing) or here; ``several`` pictures need a folder."""
    if out and Path(out).suffix.lower() == ".png" and not Path(out).is_dir():
        if several:
            raise ConfigError("one file for several pictures", file=out, key=("--out",),
                              expected="a folder for one picture per recording (NAME-VIEW.png in it)")
        return check_output_file(out, "--out")
    folder = check_output_dir(out, "--out") if out else Path(".")
    return folder / f"{name}-{view}.png"


def _show_recordings(args: argparse.Namespace, pm: PluginManager, template: str | None, files: list[str]) -> int:
    """``likeme show --body PROFILE FILE ... --view NAME``: the view's picture of the recordings, watched by the
    observer composed from the template (and ``--repertoire``, or the recordings themselves), as observe does."""
    import tempfile

    from plugins.views.demonstration import recording
    from toolkit.observe import compose_observer
    from toolkit.profile import load_profile

    if not args.view:
        raise ConfigError("recordings without --view", key=("--view",), expected="--view NAME: a view that draws "
                          "recordings", available=_recording_views(pm))
    view = _view(pm, args.view, "character", args.set)
    each = getattr(view, "recordings", None)
    if each not in ("each", "all"):
        raise ConfigError(f"view {args.view!r} does not draw recordings", key=("--view",),
                          expected="a view of recordings", available=_recording_views(pm))
    needs = dict(getattr(view, "needs", {}))
    if each == "all":
        outs = [_show_out(args.out_path, Path(files[0]).stem if len(files) == 1 else "recordings", args.view)]
    else:
        outs = [_show_out(args.out_path, Path(f).stem, args.view, several=len(files) > 1) for f in files]
    profile = load_profile(args.body)
    demos = [recording(profile, f) for f in files]  # each read (and checked) before anything is composed
    segmenter = args.segmenter or needs.get("segmenter")
    matcher = args.matcher or needs.get("matcher") or ("" if args.repertoire else None)
    with tempfile.TemporaryDirectory(prefix="likeme-show-") as tmp:
        repertoire = args.repertoire
        if not repertoire:  # the recordings themselves, a movement each: their hub poses, their paths
            repertoire = Path(tmp)
            for k, f in enumerate(files):
                folder = repertoire / f"{k:03d}-{Path(f).stem}"  # one movement per file, the same file twice too
                folder.mkdir()
                (folder / Path(f).name).symlink_to(Path(f).resolve())
        character = compose_observer(pm, profile, repertoire, template=template,
                                     segmenter=segmenter, matcher=matcher, correspondence=args.correspondence or "")
        if each == "all":
            written = view.draw(character, outs[0], recordings=demos)
        else:
            written = []
            for out, demo in zip(outs, demos):
                written += view.draw(character, out, recording=demo)
    for path in written:
        print(f"wrote {path}")
    return 0


def _recording_views(pm: PluginManager) -> list[str]:
    return [n for n in pm.registry.names("view") if getattr(pm.registry.get("view", n), "recordings", None)]


def _segment_row(o: Any) -> dict[str, Any]:
    """One observation as ``likeme observe`` reports it: the segment (and why it ends, if the segmenter says), the
    answer, and why it is unknown, as the matcher says (:class:`toolkit.components.Match`'s typed fields)."""
    row = {"start_frame": o.segment.start, "end_frame": o.segment.end, "start_s": round(o.segment.start_time, 3),
           "end_s": round(o.segment.end_time, 3), "movement": o.movement or "unknown",
           "confidence": round(o.match.confidence, 3) if o.match else 0.0,
           "decided_at_frame": o.segment.start + (o.decided_at if o.decided_at is not None else o.segment.n_frames),
           "decision_fraction": round(o.decision_fraction, 3)}
    if o.segment.reason:
        row["ends"] = o.segment.reason
    return {**row, **_why_unknown(o), **_candidates(o)}


def _candidates(observation: Any) -> dict[str, Any]:
    """The matcher's ranked candidates (B&B Fig. 13), ``[[movement, distance], ...]`` best first, when it gave any:
    path search's runners-up, the forward model's movements by prediction error (``--json`` only)."""
    match = observation.match
    if match is None or not match.candidates:
        return {}
    return {"candidates": [[str(name), round(float(d), 4)] for name, d in match.candidates]}


def _segment_text(seg: dict[str, Any]) -> str:
    """One segment as ``likeme observe`` prints it: a line, then why it ends and, for an unknown one, why."""
    line = (f"  frames {seg['start_frame']:5d}-{seg['end_frame']:<5d} ({seg['start_s']:6.2f}-{seg['end_s']:6.2f} s)  "
            f"{seg['movement']:<16} confidence {seg['confidence']:.2f}  decided at frame {seg['decided_at_frame']} "
            f"({seg['decision_fraction']:.0%} of the segment)")
    if "ends" in seg:
        line += f"\n    ends: {seg['ends']}"
    if "nearest" in seg or "reason" in seg:
        line += f"\n    {_why_text(seg)}"
    return line


def _file_error(err: LikemeError, path: str) -> str:
    """An error while reading or watching ``path``, as one line naming the file (a plugin's failure: at the end)."""
    text = str(err)
    return text if path in text else f"{text} (watching {path})"


def cmd_observe(args: argparse.Namespace, pm: PluginManager) -> int:
    """Watch recordings (``.bvh``, ``.csv``, ``.npy``, or ``-``: frames on standard input) with an observer.

    Each file is reported when it has been watched; a file that fails is reported as one ``likeme: error:`` line
    on standard error naming it, the others are still watched, and the command exits with status 1 at the end.
    """
    from toolkit.observe import NO_CORRESPONDENCE, Observer, compose_observer, observer_plugins
    from toolkit.params import check_settings, parse_settings
    from toolkit.profile import load_profile

    profile = load_profile(args.body)
    if "-" in args.files and len(args.files) > 1:
        raise ConfigError(f"'-' (standard input) with {len(args.files) - 1} other file(s)", key=("files",),
                          expected="either '-' alone (frames piped in) or recording files")
    files, failed = [], 0
    for path in args.files if args.files != ["-"] else ():
        try:  # a FIFO, a device, a directory, a missing file or an unknown format is reported before any work
            _check_recording_path(path)
            files.append(path)
        except LikemeError as err:
            failed += 1
            print(f"likeme: error: {_file_error(err, str(path))}", file=sys.stderr)
    if failed and not files:
        return 1
    for name, kind in ((args.segmenter, "segmenter"), (args.matcher, "matcher"), (args.correspondence, "correspondence")):
        if name and name != NO_CORRESPONDENCE:
            pm.registry.get(kind, name)  # an unknown name fails here, listing the registered ones
    settings = parse_settings(list(args.set))
    if args.fps is not None:  # the repertoire's clips are recordings too: the same rate, unless --set says otherwise
        settings.setdefault("motor", {}).setdefault("fps", args.fps)
    template = args.observer  # None: the observer template (toolkit.observe.OBSERVER_TEMPLATE)
    check_settings(settings, pm, observer_plugins(pm, segmenters=[args.segmenter] if args.segmenter else (),
                                                  matchers=[args.matcher] if args.matcher else (),
                                                  correspondence=args.correspondence or "", template=template))
    character = compose_observer(pm, profile, args.repertoire, segmenter=args.segmenter, matcher=args.matcher or "",
                                 correspondence=args.correspondence or "",
                                 lengths_for_height="" if args.lengths_for_height is None else args.lengths_for_height,
                                 settings=settings, template=template)
    if args.files == ["-"]:
        return _observe_live(args, character, profile, Observer)
    report = []
    for path in files:
        try:
            entry = _observe_file(path, args, character, profile, Observer)
        except LikemeError as err:
            failed += 1
            sys.stdout.flush()  # the files before it first, then its error
            print(f"likeme: error: {_file_error(err, str(path))}", file=sys.stderr)
            continue
        if args.json:
            report.append(entry)
            continue
        n = len(entry["segments"])
        print(f"{entry['file']}: {entry['frames']} frames at {entry['fps']:g} fps, {n} segment{'' if n == 1 else 's'}")
        for seg in entry["segments"]:
            print(_segment_text(seg))
    if args.json:
        print(json.dumps(report, indent=1))
    return 1 if failed else 0


def _check_recording_path(path: str) -> None:
    """A recording named on the command line: a regular file (not a FIFO, a device or a folder) of a known format."""
    from toolkit.files import check_regular_file
    from toolkit.profile import recording_format

    check_regular_file(path, "BVH file" if Path(path).suffix.lower() not in (".csv", ".npy") else
                       "recording of joint positions", "motion")
    recording_format(path)


def _observe_file(path: str, args: argparse.Namespace, character: Any, profile: Any, observer_class: Any) -> dict:
    """Watch one recording file; its report entry."""
    # the file streamed a block of frames at a time (header first), so reading memory does not grow with it
    with profile.stream(path, fps=args.fps) as motion:
        observer = observer_class(character, profile.body, motion.fps)
        observer.reset()
        found = []
        for positions, visible in motion:
            found.extend(observer.push_block(positions, visible))
        found.extend(observer.flush())
    return {"file": str(path), "frames": motion.n_frames, "fps": round(motion.fps, 3),
            "segments": [_segment_row(o) for o in found]}


def _observe_live(args: argparse.Namespace, character: Any, profile: Any, observer_class: Any) -> int:
    """``likeme observe -``: frames on standard input, each observation printed (and flushed) as its segment closes."""
    import numpy as np

    from toolkit.live import SOURCE, LiveInput

    live = LiveInput(sys.stdin.buffer, profile, args.fps if args.fps is not None else profile.fps)
    observer = observer_class(character, profile.body, live.fps)
    observer.reset()
    count = frames = 0

    def emit(observations: list) -> None:
        nonlocal count
        for o in observations:
            seg = _segment_row(o)
            count += 1
            print(json.dumps({"file": SOURCE, **seg}) if args.json else _segment_text(seg), flush=True)

    if not args.json:
        print(f"{SOURCE}: standard input at {live.fps:g} fps", flush=True)
    for positions in live:
        frames += 1
        emit(observer.push(positions, np.isfinite(positions).all(axis=-1)))
    emit(observer.flush())
    if not args.json:
        print(f"{SOURCE}: {frames} frames at {round(live.fps, 3):g} fps, {count} segment{'' if count == 1 else 's'}",
              flush=True)
    return 0


def _why_unknown(observation: Any) -> dict[str, Any]:
    """For an unknown segment: why, as the matcher said (the nearest movement, the reason, the score it was rejected
    on and the threshold it exceeded, with what they measure), else nothing."""
    match = observation.match
    if match is None or match.movement is not None:
        return {}
    out: dict[str, Any] = {}
    if match.nearest:
        out["nearest"] = str(match.nearest)
    if match.reason:
        out["reason"] = str(match.reason)
    for key in ("score", "threshold"):
        value = getattr(match, key)
        if isinstance(value, (int, float)) and math.isfinite(value):
            out[key] = float(f"{float(value):.4g}")  # four significant digits: a threshold of 1e-9 stays one
    if match.measure and ("score" in out or "threshold" in out):
        out["measure"] = str(match.measure)
    return out


def _why_text(seg: dict[str, Any]) -> str:
    """One line: 'nearest bow, rejected: too far from every path (mean pose distance ... 0.081 > 0.03)'."""
    nearest = f"nearest {seg['nearest']}" if "nearest" in seg else "no nearest movement"
    numbers = ""
    if "score" in seg:
        numbers = f"{seg.get('measure', 'score')} {seg['score']:g}" + (f" > {seg['threshold']:g}" if "threshold" in
                                                                       seg else "")
    return f"{nearest}, rejected: {seg.get('reason', 'no reason given')}" + (f" ({numbers})" if numbers else "")


def cmd_validate(args: argparse.Namespace, pm: PluginManager) -> int:
    from toolkit.bvh import open_bvh
    from toolkit.character import COMPONENT_TABLES, load_character, read_toml
    from toolkit.files import check_regular_file
    from toolkit.observe import check_observer_template, is_observer_template
    from toolkit.profile import is_profile, load_profile
    from toolkit.report import describe_character
    from toolkit.scenario import is_scenario, load_scenario

    failed = warned = 0
    try:
        profile = load_profile(args.body) if args.body else None
    except LikemeError as err:
        print(f"likeme: error: {err}", file=sys.stderr)
        return 1
    flips: list[tuple[str, Any, int]] = []  # where the facing flips in each recording, counted over them all
    if profile is not None:
        warned += _warn(args.body, _profile_warnings(profile))
    for path in args.files:
        try:
            suffix = Path(path).suffix.lower()
            if suffix == ".bvh":
                with open_bvh(path) as bvh:  # every frame read and checked, a block at a time
                    for _ in bvh.blocks():
                        pass
                line = f"ok    {path}: BVH: {len(bvh.names)} joints, {bvh.n_frames} frames at {bvh.fps:g} fps"
                if profile is not None:
                    unmapped = profile.check(bvh.header)
                    line += f"; profile {profile.name!r} maps {len(profile.joints)}, leaves {len(unmapped)} unmapped"
                print(line)
                if profile is not None:  # where the profile is probably wrong for this file (plugins/lib/profile_check)
                    warned += _warn(path, _recording_warnings(profile, path, flips))
                continue
            if suffix in (".csv", ".npy"):
                print(_validate_positions(path, profile, args.fps))
                continue
            table = read_toml(check_regular_file(path, "TOML file", "config"))
            if is_scenario(table):
                scenario = load_scenario(path, pm)
                world = scenario.world
                print(f"ok    {path}: scenario {scenario.name!r}: {len(world.actors)} actor(s) ({', '.join(world.actors)}), {len(world.objects)} object(s)")
            elif is_observer_template(table):
                plugins = check_observer_template(path, pm)
                comps = ", ".join(f"{k} {v}" for k, v in plugins.items())
                print(f"ok    {path}: observer template: {comps} (a body profile and clips complete it)")
            elif is_profile(table):
                prof = load_profile(path)
                print(f"ok    {path}: body profile {prof.name!r}: {len(prof.joints)} parts, units {prof.scale:g} m, up {prof.up}")
                warned += _warn(path, _profile_warnings(prof))
            else:
                c = describe_character(load_character(path, pm))
                comps = ", ".join(f"{k} {c[k]['plugin']}" for k in COMPONENT_TABLES if k in c)
                moves = c["motor"].get("movements")
                print(f"ok    {path}: character {c['name']!r}: {c['parts']} parts, {moves} movements; {comps}")
        except LikemeError as err:
            failed += 1
            print(f"likeme: error: {err}", file=sys.stderr)
    if flips:
        from plugins.lib.profile_check import facing_warnings

        warned += sum(_warn(path, [text]) for path, text in facing_warnings(flips))
    return 1 if failed or (warned and args.strict) else 0


def _warn(source: str | Path, warnings: list[str]) -> int:
    """Print each warning as ``likeme: warning: SOURCE: ...`` on standard error; return how many."""
    for text in warnings:
        print(f"likeme: warning: {source}: {text}", file=sys.stderr)
    return len(warnings)


def _profile_warnings(profile: Any) -> list[str]:
    from plugins.lib.profile_check import profile_warnings

    return profile_warnings(profile)


def _recording_warnings(profile: Any, path: str | Path, flips: list[tuple[str, Any, int]]) -> list[str]:
    """Where ``profile`` is probably wrong for the recording ``path`` (units, up axis), read a block at a time; the
    frames where its facing flips are added to ``flips``, to be counted over every recording."""
    from plugins.lib.profile_check import RecordingCheck

    check = RecordingCheck(profile)
    with profile.stream(path) as blocks:
        for positions, visible in blocks:
            check.update(positions, visible)
    flips.append((str(path), *check.flips()))
    return check.warnings(facing=False)


PROFILE_FRAMES = 20_000
"""The frames of a recording ``likeme profile`` reads (from its start): enough to see a body's size, up and facing."""


def _read_recording(path: str) -> tuple[list[str], Any, list[int] | None, float | None, int]:
    """A recording's joint names, positions (F, J, 3) in its own units and axes (at most :data:`PROFILE_FRAMES`),
    hierarchy (BVH) or None, frame rate (None: the file does not tell) and number of frames."""
    import numpy as np

    suffix = Path(path).suffix.lower()
    if suffix == ".bvh":
        from toolkit.bvh import open_bvh

        with open_bvh(path) as bvh:
            header, kept, count = bvh.header, [], 0
            for values in bvh.blocks():
                kept.append(header._kinematics(values[: PROFILE_FRAMES - count])[0])
                count += len(kept[-1])
                if count >= PROFILE_FRAMES:
                    break
            positions = np.concatenate(kept) if kept else np.zeros((0, len(bvh.names), 3))
            return list(bvh.names), positions, [j.parent for j in bvh.joints], bvh.fps, bvh.n_frames
    if suffix in (".csv", ".c3d"):  # joint positions with their names (a C3D file: its labelled points)
        from toolkit.positions import iter_position_blocks

        fps: float | None = None
        try:
            header, blocks = iter_position_blocks(path)
            fps = header.fps
        except ConfigError as err:
            if "frame rate" not in str(err):
                raise
            header, blocks = iter_position_blocks(path, fps=1.0)  # no time column: the proposal needs no frame rate
        kept, count = [], 0
        for block in blocks:
            kept.append(block[: PROFILE_FRAMES - count])
            count += len(kept[-1])
            if count >= PROFILE_FRAMES:
                break
        positions = np.concatenate(kept) if kept else header.positions
        return list(header.names), positions, None, fps, len(positions)
    raise ConfigError(f"cannot propose a profile for a {suffix or 'suffix-less'} file", file=path, key=("FILE",),
                      expected="a BVH file, a CSV of joint positions or a C3D file (a .npy array has no joint "
                               "names)", available=(".bvh", ".csv", ".c3d"))


def cmd_profile(args: argparse.Namespace, pm: PluginManager) -> int:
    """Propose a body profile for a recording (``plugins.lib.profile_check.propose_profile``), check it on the same
    recording, and print it or write it to ``--out``; what it could not decide is marked ``# TODO``."""
    import tempfile

    import numpy as np

    from plugins.lib.profile_check import propose_profile, recording_warnings
    from toolkit.files import check_regular_file
    from toolkit.profile import load_profile
    from toolkit.state import write_atomic

    check_regular_file(args.file, "recording", "motion")
    names, positions, parents, fps, frames = _read_recording(args.file)
    if len(positions) == 0:
        raise ConfigError("no frames", file=args.file, expected="a recording with at least one frame")
    stem = re.sub(r"[^A-Za-z0-9_-]+", "-", Path(args.out or args.file).stem).strip("-") or "proposed"
    proposal = propose_profile(names, positions, parents=parents, name=stem, source=Path(args.file).name, fps=fps)
    with tempfile.TemporaryDirectory() as tmp:  # the proposal must load and pass its own checks on this recording
        draft = Path(tmp) / f"{stem}.toml"
        draft.write_text(proposal.text, encoding="utf-8")
        profile = load_profile(draft)
    converted = profile.convert(positions, names)
    warnings = recording_warnings(profile, [(converted, np.isfinite(converted).all(axis=-1))])
    if args.out:
        write_atomic(args.out, proposal.text)
        print(f"wrote {args.out}", file=sys.stderr)
    else:
        print(proposal.text, end="")
    if len(positions) < frames:
        print(f"likeme: note: {args.file}: proposed from the first {len(positions)} of {frames} frames",
              file=sys.stderr)
    for text in proposal.todo:
        print(f"likeme: note: {args.file}: TODO: {text}", file=sys.stderr)
    _warn(args.file, warnings)
    return 0


def _validate_positions(path: str, profile: Any, fps: float | None) -> str:
    """``likeme validate`` of a CSV or ``.npy`` recording: every frame read and checked, a block at a time; with a
    profile, its joints checked against the profile's and read as it reads them."""
    import numpy as np

    from toolkit.positions import iter_position_blocks

    kind = "CSV" if Path(path).suffix.lower() == ".csv" else "NumPy array"
    rate = fps if fps is not None or profile is None else profile.fps
    if profile is not None:
        names = profile.npy_joints if kind != "CSV" else None
    elif kind != "CSV":
        names = _npy_joint_names(path)
    else:
        names = None
    header, blocks = iter_position_blocks(path, names=names, fps=rate)
    unmapped = profile.check(header) if profile is not None else []
    frames = hidden = 0
    for block in blocks:
        frames += len(block)
        hidden += int((~np.isfinite(block).all(axis=-1)).sum())
    line = (f"ok    {path}: {kind}: {len(header.names)} joints, {frames} frames at {header.fps:g} fps, "
            f"{hidden} missing joint positions")
    if profile is not None:
        line += f"; profile {profile.name!r} maps {len(profile.joints)}, leaves {len(unmapped)} unmapped"
    return line


def _npy_joint_names(path: str) -> list[str] | None:
    """Placeholder joint names (``joint_0``...) for a ``.npy`` array validated without a profile, or None when its
    header is not that of an array of joints (the reader then names what is wrong)."""
    import numpy as np

    from toolkit.files import check_regular_file

    check_regular_file(path, "recording of joint positions", "motion")
    try:
        shape = np.load(path, mmap_mode="r", allow_pickle=False).shape
    except (ValueError, OSError, EOFError):
        return None
    return [f"joint_{k}" for k in range(shape[1])] if len(shape) == 3 and 0 < shape[1] <= 10_000 else None


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
