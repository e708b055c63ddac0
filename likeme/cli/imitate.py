"""``likeme imitate``: a demonstration watched by an observer and performed with its own movements, written out.

The observer ``likeme observe`` composes (a body profile, a folder of labelled clips, an observer template) parses
the demonstration with its segmenter, recognises each segment with its matcher and performs what it recognised
with its own movements at the demonstrator's timing (Buchsbaum & Blumberg 2005, §5.3; Kopp & Graeser 2006, §4.4);
a segment it does not know it learns (B&B §7.3, K&G §4.3) and performs as the demonstrator did it. The imitation is
written in the observer's skeleton (:mod:`likeme.imitation`), the learned movements into a repertoire folder
(``--learn-into``).
"""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

from toolkit.arguments import fps_type, number_type, observer_options

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle"]


def add_parser(sub: Any) -> None:
    """``likeme imitate``."""
    p = sub.add_parser("imitate", help="perform a demonstration with the observer's own movements (learning what it "
                       "does not know) and write it out in its skeleton")
    p.add_argument("file", metavar="FILE", help="the demonstration: a recording (.bvh, .csv, .npy; docs/formats.md)")
    p.add_argument("--body", required=True, metavar="PROFILE", help="body profile TOML of the demonstration and of "
                   "the repertoire (the observer's skeleton)")
    p.add_argument("--repertoire", required=True, metavar="DIR", help="the observer's movements: one folder of "
                   "clips per movement")
    p.add_argument("--demo-body", metavar="PROFILE", dest="demo_body", help="body profile of the demonstration when "
                   "it was recorded with another skeleton (the same parts by name; default: --body)")
    p.add_argument("--out", required=True, metavar="FILE", help="where the imitation is written: .bvh or .csv")
    p.add_argument("--learn-into", metavar="DIR", dest="learn_into", help="write each movement learned into this "
                   "repertoire folder (DIR/NAME/FILE.bvh; the repertoire itself, to know them next time)")
    p.add_argument("--no-learn", action="store_true", dest="no_learn", help="do not learn unknown segments (they "
                   "are left standing in the hub)")
    p.add_argument("--transition", type=number_type(0.0, 10.0, "seconds"), default=0.2, metavar="S",
                   help="seconds over which each join between movements is blended (default 0.2)")
    p.add_argument("--timing", choices=("duration", "aligned"), default="duration",
                   help="how each recognised movement is timed to its segment: duration (played evenly over it, the "
                   "speed re-parameterised, K&G §4.4; the default) or aligned (time-warped onto the demonstrator's "
                   "poses, pose by pose)")
    p.add_argument("--fps", type=fps_type, default=None, metavar="HZ", help="frame rate of recordings without one "
                   "of their own")
    p.add_argument("--segmenter", metavar="NAME", help="segmenter (default: the observer template's)")
    p.add_argument("--matcher", metavar="NAME", help="matcher (default: the observer template's)")
    observer_options(p)
    p.add_argument("--json", action="store_true", help="print the segments and the figures as JSON")
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace, pm: PluginManager) -> int:
    """Imitate the demonstration, write it (and what was learned); print what was performed where."""
    from likeme.cli.observe import _check_recording_path
    from likeme.imitation import OUTPUT_SUFFIXES, imitate, save_learned, segment_rows, write_motion
    from toolkit.arguments import check_output_dir
    from toolkit.config.settings import check_settings, parse_settings
    from toolkit.errors import ConfigError
    from toolkit.observe import observer_plugins
    from toolkit.recordings.profile import load_profile

    if not args.out.lower().endswith(OUTPUT_SUFFIXES):
        raise ConfigError(f"cannot write {args.out!r}", key=("--out",), expected="a file name ending in "
                          + " or ".join(OUTPUT_SUFFIXES))
    if args.learn_into and args.no_learn:
        raise ConfigError("--learn-into with --no-learn", key=("--learn-into",), expected="one of them")
    if args.learn_into:
        check_output_dir(args.learn_into, "--learn-into")
    _check_recording_path(args.file)
    profile = load_profile(args.body)
    settings = parse_settings(list(args.set))
    if args.fps is not None:
        settings.setdefault("motor", {}).setdefault("fps", args.fps)
    check_settings(settings, pm, observer_plugins(pm, segmenters=[args.segmenter] if args.segmenter else (),
                                                  matchers=[args.matcher] if args.matcher else (),
                                                  correspondence=args.correspondence or "", template=args.observer))
    result = imitate(profile, args.repertoire, args.file, segmenter=args.segmenter, matcher=args.matcher or "",
                     correspondence=args.correspondence or "", template=args.observer, settings=settings,
                     learn=not args.no_learn, transition=args.transition, fps=args.fps, pm=pm,
                     lengths_for_height="" if args.lengths_for_height is None else args.lengths_for_height,
                     demonstration_profile=args.demo_body, timing=args.timing)
    written = write_motion(result.motion, profile, args.out)
    saved = save_learned(result, args.learn_into) if args.learn_into else []
    error = result.error()
    if args.json:
        print(json.dumps({"file": args.file, "out": str(written), "frames": result.motion.n_frames,
                          "fps": round(result.motion.fps, 3), "segments": segment_rows(result),
                          "learned": {name: str(path) for name, path in zip(result.learned, saved)}
                          if saved else sorted(result.learned),
                          "error_body_sizes": None if error != error else round(error, 4)}, indent=1))
        return 0
    n = len(result.segments)
    print(f"{args.file}: {result.motion.n_frames} frames at {result.motion.fps:g} fps, {n} segment"
          f"{'' if n == 1 else 's'} performed")
    for row in segment_rows(result):
        how = "learned, performed as demonstrated" if row["learned"] else f"confidence {row['confidence']:.2f}"
        print(f"  frames {row['start_frame']:5d}-{row['end_frame']:<5d} ({row['start_s']:6.2f}-{row['end_s']:6.2f} s)"
              f"  {row['movement']:<16} {how}")
    if error == error:
        print(f"poses within {error:.3f} body sizes of the demonstrator's (mean over the segments, aligned)")
    print(f"wrote {written}")
    for path in saved:
        print(f"learned {path.parent.name}: {path}")
    if result.learned and not saved:
        print(f"learned {', '.join(result.learned)} (not saved: --learn-into DIR writes them)")
    return 0
