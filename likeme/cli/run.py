"""``likeme demo`` and ``likeme run``: scenarios run and reported (what each character did, saw and made of it).

``run`` also restores and saves what the characters learn (``--load``, ``--save``: :mod:`toolkit.state`) and draws
the run with a scenario view (``--render DIR``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from likeme.cli.common import view_of
from toolkit.arguments import number_type, seed_type
from toolkit.errors import ConfigError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle_demo", "handle_run", "DEMO_SCENARIOS"]


DEMO_SCENARIOS = ("demo", "ice_cream", "imitation_games", "hand_games", "hand_arm_games")
"""What ``likeme demo`` runs: Max imitating Morris's random movements, Max working out why Morris eats,
Max learning Moritz's arm movements in three imitation games and his finger movements in three more, and
following Moritz's wrist and hand at once in the hand-arm games."""


def add_parser(sub: Any) -> None:
    """``likeme demo`` and ``likeme run``."""
    p = sub.add_parser("demo", help="run the built-in scenario and report what each character did and saw")
    p.add_argument("--seed", type=seed_type, default=None, help="seed for random choices (default: the scenario's)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--keep-going", action="store_true", help="go on without a plugin that fails (default: stop)")
    p.add_argument("--scenario", action="append", metavar="NAME",
                   help=f"built-in scenario to run, repeatable (default: {' and '.join(DEMO_SCENARIOS)})")
    p.set_defaults(handler=handle_demo)

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
    p.set_defaults(handler=handle_run)


def _run_scenario(path: str, pm: PluginManager, args: argparse.Namespace) -> dict[str, Any]:
    from toolkit.report import summarise
    from toolkit.scenario import load_scenario
    from toolkit.state import Checkpoint, StateFile, apply_state, read_state

    if getattr(args, "set", None) and not getattr(args, "render", None):  # a view's settings, and no view
        raise ConfigError("--set without --render", key=("--set",),
                          expected="--render DIR with the settings of the view that draws the run")
    # the --save target and the --load file are checked before any work (the target first: its version is the one
    # this run may overwrite); the loaded state is applied, all or nothing, once the world is composed
    # (an empty name is an error naming the option, not "no --save")
    save = getattr(args, "save", None)
    target = StateFile(save, loaded=getattr(args, "load", None)) if save is not None else None
    loaded = read_state(args.load) if getattr(args, "load", None) is not None else None
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
    view = view_of(pm, args.view, "scenario", args.set) if getattr(args, "render", None) else None
    files = []
    try:
        if view is not None:  # a scenario view runs the scenario while it records it, then draws it, all files at once
            from toolkit.files import writing_folder

            folder = Path(args.render)
            with writing_folder(folder, "render") as stage:
                files = [folder / Path(f).relative_to(stage) for f in view.draw(scenario, stage)]
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


def handle_demo(args: argparse.Namespace, pm: PluginManager) -> int:
    """Run the built-in scenarios (:data:`DEMO_SCENARIOS` unless ``--scenario`` names others)."""
    _print([_run_scenario(name, pm, args) for name in (args.scenario or DEMO_SCENARIOS)], args.json)
    return 0


def handle_run(args: argparse.Namespace, pm: PluginManager) -> int:
    _print([_run_scenario(args.scenario, pm, args)], args.json)
    return 0
