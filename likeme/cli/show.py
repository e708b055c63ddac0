"""``likeme show``: a character's representations, the observer ``likeme observe`` composes, or one's own recordings,
as text (JSON, the action system) or drawn by a view to PNG (``--view NAME``)."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

from likeme.cli.common import view_of
from toolkit.arguments import check_output_dir, check_output_file
from toolkit.errors import ConfigError

if TYPE_CHECKING:  # pragma: no cover
    from collections.abc import Callable

    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle"]


def add_parser(sub: Any) -> None:
    """``likeme show``."""
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
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace, pm: PluginManager) -> int:
    from toolkit.character import load_character
    from toolkit.report import describe_character

    for option, value in (("--set", args.set), ("--out", args.out_path)):
        if value and not args.view:  # a view's settings and picture: nothing to apply them to
            raise ConfigError(f"{option} without --view", key=(option,),
                              expected="--view NAME with the view's settings and where it writes its picture")
    from toolkit.recordings import SUFFIXES, is_recording

    files = [f for f in args.character if is_recording(f)]
    names = [f for f in args.character if f not in files]
    if len(names) > 1 or (files and args.after) or (files and not args.body):
        raise ConfigError(f"cannot show {' and '.join(names) if len(names) > 1 else ' '.join(args.character)}",
                          key=("character",), expected="one character (or observer template), or with --body PROFILE "
                          f"recordings ({', '.join(SUFFIXES)}) after an optional observer template")
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
        from toolkit.recordings.profile import load_profile

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
        view = view_of(pm, args.view, "character", args.set)
        name = re.sub(r"[^a-z0-9]+", "-", character.name.lower()).strip("-")
        out = _show_out(args.out_path, name, args.view)
        for path in _drawn([out], lambda staged: view.draw(character, staged[0])):
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


def _drawn(outs: list[Path], draw: Callable[[list[Path]], list[Path]]) -> list[Path]:
    """The files ``draw`` writes for the pictures ``outs`` (all in one folder), drawn into a staging folder there
    and moved in when all are written (:func:`toolkit.files.writing_folder`): a full disk or a read-only folder is
    one error naming it, and no half-written picture is left."""
    from toolkit.files import writing_folder

    folder = outs[0].parent
    what = "picture " + ", ".join(o.name for o in outs[:3]) + (f" and {len(outs) - 3} more" if len(outs) > 3 else "")
    with writing_folder(folder, what) as stage:
        written = [Path(w) for w in draw([stage / o.name for o in outs])]
    return [folder / w.relative_to(stage) if w.is_relative_to(stage) else w for w in written]


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
    from plugins.lib.clip_repertoire import clip_repertoire
    from plugins.views.demonstration import recording
    from toolkit.observe import compose_observer
    from toolkit.recordings.profile import load_profile

    if not args.view:
        raise ConfigError("recordings without --view", key=("--view",), expected="--view NAME: a view that draws "
                          "recordings", available=_recording_views(pm))
    view = view_of(pm, args.view, "character", args.set)
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
    repertoire = args.repertoire
    if not repertoire:  # the recordings themselves, a movement each (the same file twice too): their hubs, their paths
        repertoire = clip_repertoire([demo.motion for demo in demos],
                                     [f"{k:03d}-{Path(f).stem}" for k, f in enumerate(files)], profile,
                                     sources=[Path(f) for f in files])
    character = compose_observer(pm, profile, repertoire, template=template,
                                 segmenter=segmenter, matcher=matcher, correspondence=args.correspondence or "")
    if each == "all":
        written = _drawn(outs, lambda staged: view.draw(character, staged[0], recordings=demos))
    else:
        written = _drawn(outs, lambda staged: [w for out, demo in zip(staged, demos)
                                               for w in view.draw(character, out, recording=demo)])
    for path in written:
        print(f"wrote {path}")
    return 0


def _recording_views(pm: PluginManager) -> list[str]:
    return [n for n in pm.registry.names("view") if getattr(pm.registry.get("view", n), "recordings", None)]
