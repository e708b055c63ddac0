"""``likeme observe``: recordings (or frames piped in on standard input) watched by an observer composed from a body
profile, a folder of labelled clips and an observer template; each segment printed with the movement recognised,
when it was decided, why it ends and, when it is unknown, why (the segmenter's and the matcher's own words:
:class:`toolkit.components.Segment` and :class:`toolkit.components.Match`'s typed fields)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit.arguments import fps_type, observer_options
from toolkit.errors import ConfigError, LikemeError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["add_parser", "handle"]


def add_parser(sub: Any) -> None:
    """``likeme observe``."""
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
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace, pm: PluginManager) -> int:
    """Watch recordings (``.bvh``, ``.csv``, ``.npy``, or ``-``: frames on standard input) with an observer.

    Each file is reported when it has been watched; a file that fails is reported as one ``likeme: error:`` line
    on standard error naming it, the others are still watched, and the command exits with status 1 at the end.
    """
    from toolkit.observe import NO_CORRESPONDENCE, Observer, compose_observer, observer_plugins
    from toolkit.config.settings import check_settings, parse_settings
    from toolkit.recordings.profile import load_profile

    profile = load_profile(args.body)
    if "-" in args.files and len(args.files) > 1:
        raise ConfigError(f"'-' (standard input) with {len(args.files) - 1} other file(s)", key=("files",),
                          expected="either '-' alone (frames piped in) or recording files")
    if args.files == ["-"] and sys.stdin is None:  # started with standard input closed (`<&-`): before any work
        from toolkit.recordings.live import SOURCE

        raise ConfigError("standard input is closed", file=Path(SOURCE),
                          expected="frames on standard input (a pipe or a file), or recordings named as files")
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
    template = args.observer  # None: the observer template (toolkit.config.observer_templates.OBSERVER_TEMPLATE)
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
        if not n and entry["frames"] and character.segmenter.none_found:
            print(f"  no movement: {character.segmenter.none_found}")
    if args.json:
        print(json.dumps(report, indent=1))
    return 1 if failed else 0


def _check_recording_path(path: str) -> None:
    """A recording named on the command line: a regular file (not a FIFO, a device or a folder) of a known format."""
    from toolkit.files import check_regular_file
    from toolkit.recordings import recording_format

    check_regular_file(path, "BVH file" if Path(path).suffix.lower() not in (".csv", ".npy", ".c3d") else
                       "recording of joint positions", "motion")
    recording_format(path)


def _file_error(err: LikemeError, path: str) -> str:
    """An error while reading or watching ``path``, as one line naming the file (a plugin's failure: at the end)."""
    text = str(err)
    return text if path in text else f"{text} (watching {path})"


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
    """``likeme observe -``: frames on standard input, each observation printed (and flushed) as its segment closes.

    The frames are read as they arrive and watched a block of those that have arrived at a time
    (:meth:`toolkit.recordings.live.LiveInput.blocks`; one frame when the observer keeps up): the observations are
    those of pushing them one by one (:meth:`toolkit.observe.Observer.push_block`), and an observer that fell behind
    (while it was composed, or on a slow frame) catches up at the speed of its block paths."""
    import numpy as np

    from toolkit.recordings.live import SOURCE, LiveInput

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
    for block in live.blocks():  # every frame that has arrived at once: a reader that fell behind catches up
        frames += len(block)
        emit(observer.push_block(block, np.isfinite(block).all(axis=-1)))
    emit(observer.flush())
    if not args.json:
        print(f"{SOURCE}: {frames} frames at {round(live.fps, 3):g} fps, {count} segment{'' if count == 1 else 's'}",
              flush=True)
    return 0


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
