"""Benchmarks on motion-capture files: ``likeme bench recognition|segmentation|stream``.

Every sub-command reads recordings (BVH, CSV joint positions or ``.npy`` arrays, by suffix; a folder may mix them)
through a body profile (:mod:`toolkit.recordings.profile`) and watches them with
:class:`toolkit.observe.Observer`, so the toolkit's segmenters and matchers and the baselines (``dtw``,
``ruptures``) are measured on the same clips in the same loop:

- ``recognition``: each demo clip (a folder per true movement) is one segment; every matcher named classifies it.
  Accuracy, macro F1, the confusion matrix, the decision fraction (share of the clip seen when the matcher
  committed; 1.0 for matchers that wait for the end) and frames per second. Protocols: ``closed`` (every demo
  against the whole repertoire), ``open`` (leave one movement out: only "unknown" is right) and ``groups`` (leave
  one group out: the repertoire folder's clips whose file names share a group, a style or a performer, are the
  demos of a repertoire made of all the other clips).
- ``segmentation``: each stream ``NAME.bvh`` (or ``.csv``, ``.npy``) has ``NAME.segments.csv``
  (:mod:`toolkit.recordings.segments`).
  Precision, recall, F1, the mean boundary error in frames and the share of true boundaries found within 0.25 s
  (:mod:`plugins.bench.metrics`) per segmenter.
- ``stream``: segment and recognise end to end for every pairing; the movement error rate (edit distance over the
  true count).

The folders are written by ``likeme bench make-data`` and ``likeme bench bandai`` (:mod:`plugins.bench.data`).
"""

from __future__ import annotations

import csv
import gc
import io
import json
import platform
import re
import time
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from plugins.bench import progress as progress_bar
from plugins.bench import text_table
from plugins.bench.command import MATCHERS, SEGMENTERS
from plugins.bench.metrics import confusion_matrix, macro_f1, movement_error_rate, segmentation_scores
from plugins.bench.tracker import jittered
from plugins.lib.clip_repertoire import clip_files
from toolkit import ConfigError
from toolkit.observe import Observer, compose_observer
from toolkit.recordings import is_recording
from toolkit.recordings.segments import read_segments, segments_of
from toolkit.recordings.profile import load_profile

__all__ = ["MATCHERS", "SEGMENTERS", "recognition", "segmentation", "stream", "cell", "merge", "table",
           "write_outputs", "plot", "run"]






def _labelled(folder: Path) -> list[tuple[str, Path]]:
    return [(label, p) for label, files in clip_files(folder).items() for p in files]


def _streams(folder: Path) -> list[tuple[Path, list[tuple[int, int, str]]]]:
    """The recordings of a streams folder (``NAME.bvh``, ``.csv`` or ``.npy``, any mix) with their true segments."""
    files = sorted(p for p in Path(folder).iterdir() if is_recording(p)) if Path(folder).is_dir() else []
    if not files:
        raise ConfigError("no streams found", file=folder,
                          expected="NAME.bvh (or NAME.csv, NAME.npy) files with NAME.segments.csv beside them")
    out = []
    for path in files:
        csv_path = segments_of(path)
        if not csv_path.exists():
            raise ConfigError("missing segment file", file=csv_path, expected=f"the true segments of {path.name}")
        out.append((path, read_segments(csv_path)))
    return out


def _settings(values: Sequence[str]) -> dict[str, dict[str, Any]]:
    from toolkit.config.settings import parse_settings

    return parse_settings(list(values))


def _with_clip_rate(settings: Mapping[str, Mapping[str, Any]] | None, fps: float | None) -> dict[str, dict[str, Any]]:
    """``settings`` with the motor system reading the repertoire's clips at ``fps`` when they have no rate of their
    own, as the demos and streams are read (a ``motor.fps`` given in ``settings`` wins)."""
    settings = {table: dict(values) for table, values in (settings or {}).items()}
    if fps is not None:
        settings.setdefault("motor", {}).setdefault("fps", fps)
    return settings


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("likeme", "numpy", "scipy", "networkx", "dtaidistance", "ruptures"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


class _Clock:
    """Runs an observer over motions and counts the frames and the seconds spent, for frames per second."""

    def __init__(self, character, profile) -> None:
        self.character, self.profile, self.frames, self.seconds = character, profile, 0, 0.0
        # Set-up's garbage (this observer's composition, earlier pairings' observers) collected before any clock
        # starts, as a long-running observer's would be long before it watched for a while. Without it a full
        # collection of everything the process built before lands in whichever loop crosses the collector's
        # threshold: velocity-direction + path-search measured 28,500 frames/s after the three hub-threshold
        # pairings and 37,800 alone, the same code. The collections the loop's own objects cause are still timed.
        gc.collect()

    def run(self, how: str, motion):
        """``Observer.watch`` or ``Observer.classify`` on ``motion``, timed."""
        observer = Observer(self.character, self.profile.body, motion.fps)
        t0 = time.perf_counter()
        out = getattr(observer, how)(motion)
        self.seconds += time.perf_counter() - t0
        self.frames += motion.n_frames
        return out

    @property
    def fps(self) -> float:
        return self.frames / max(self.seconds, 1e-9)


def _progress(items: list, label: str, quiet: bool):
    if quiet:
        return items
    return progress_bar(items, label)


PROTOCOLS = ("closed", "open", "groups", "takes")


def _finite(value: float | None) -> float | None:
    """A matcher's score or threshold for a JSON row: six significant digits, or ``None`` where there is none."""
    return float(f"{float(value):.6g}") if value is not None and np.isfinite(value) else None


def recognition(pm, profile, repertoire: Path, demos: Path | None, matchers: Sequence[str], *, settings=None,
                quiet: bool = True, observer: dict[str, Any] | None = None, protocol: str = "closed",
                group: str | None = None, fps: float | None = None) -> dict[str, Any]:
    """Classify every demo clip with every matcher; per-plugin scores and per-item rows.

    A demo whose movement (its folder's name) is not in the repertoire is right when it is answered "unknown".
    ``protocol``: ``"closed"`` classifies every demo against the whole repertoire; ``"open"`` (leave one movement
    out) classifies the demos of each movement against the repertoire without that movement, so every demo is of
    a movement the observer does not know and only "unknown" is right: the rejection rate; ``"groups"`` (leave one
    group out, no ``demos``) takes the repertoire's own clips, groups them by the first capture group of the
    regular expression ``group`` searched in each file's name (a style, a performer, a session), and classifies
    each group's clips against a repertoire of every other group's clips; ``"takes:N"`` takes the first N clips
    of each movement's folder (sorted by name: takes recorded one after another) as the repertoire, and classifies
    the folder's other clips and every demo (``demos``, optional) against it: what a user with N takes of each
    movement has. ``observer``: further arguments of
    :func:`toolkit.observe.compose_observer` (``correspondence``, ``lengths_for_height``, ``template``).
    """
    observer, settings = dict(observer or {}), _with_clip_rate(settings, fps)
    runs = _runs(profile, Path(repertoire), demos, protocol, group, fps)
    plugins, rows = [], []
    for name in matchers:
        truth, predicted, fractions, frames, seconds = [], [], [], 0, 0.0
        for (left_movement, left_files, run_group), group_items in runs:
            with _repertoire_without(Path(repertoire), left_movement, left_files) as folder:
                clock = _Clock(compose_observer(pm, profile, folder, matcher=name, settings=settings, **observer),
                               profile)
                movements = set(clock.character.motor.movements())
                for label, path, motion in _progress(group_items, f"recognition {name}", quiet):
                    obs = clock.run("classify", motion)
                    expected = label if label in movements else UNKNOWN
                    truth.append(expected)
                    predicted.append(obs.movement or UNKNOWN)
                    fractions.append(obs.decision_fraction)
                    match = obs.match
                    rows.append({"plugin": name, "item": path.name, "truth": expected, "movement": label,
                                 "group": run_group or "",
                                 "recognised": obs.movement or UNKNOWN,
                                 "nearest": str((match.nearest if match else None) or obs.movement or ""),
                                 "reason": str(match.reason if match else ""),
                                 "score": _finite(match.score if match else None),
                                 "threshold": _finite(match.threshold if match else None),
                                 "confidence": round(match.confidence, 4) if match else 0.0,
                                 "decision_fraction": round(obs.decision_fraction, 4), "frames": motion.n_frames})
                frames, seconds = frames + clock.frames, seconds + clock.seconds
        labels = sorted(set(truth) | set(predicted))
        confusion = confusion_matrix(truth, predicted, labels)
        right = [t == p for t, p in zip(truth, predicted)]
        seen = [r for r, t in zip(right, truth) if t != UNKNOWN]
        unseen = [r for r, t in zip(right, truth) if t == UNKNOWN]
        plugins.append({"plugin": name, "accuracy": float(np.mean(right)),
                        "known_accuracy": float(np.mean(seen)) if seen else float("nan"),
                        "rejection": float(np.mean(unseen)) if unseen else float("nan"),
                        "macro_f1": macro_f1(truth, predicted), "decision_median": float(np.median(fractions)),
                        "decision_p90": float(np.percentile(fractions, 90)), "fps": frames / max(seconds, 1e-9),
                        "items": len(truth), "labels": labels, "confusion": confusion.tolist()})
    return {"benchmark": "recognition", "protocol": protocol, "plugins": plugins, "items": rows}


UNKNOWN = "unknown"
"""What a demo of a movement the observer does not know should be answered."""


def _runs(profile, repertoire: Path, demos: Path | None, protocol: str, group: str | None, fps: float | None = None):
    """The protocol's runs: ((movement left out, files left out, group), [(label, path, motion)...]) each."""
    name, _, takes = protocol.partition(":")
    if name not in PROTOCOLS or (name == "takes") != bool(takes) or (takes and not takes.isdigit()):
        raise ConfigError(f"unknown protocol {protocol!r}", key=("protocol",), expected="a protocol",
                          available=["closed", "open", "groups", "takes:N"])
    if protocol == "groups":
        return _group_runs(profile, repertoire, group, fps)
    if name == "takes":
        return _take_runs(profile, repertoire, demos, int(takes), fps)
    if demos is None:
        raise ConfigError(f"protocol {protocol!r} needs demo clips", key=("demos",),
                          expected="--demos DIR: one folder of clips per true movement")
    motions = [(label, path, profile.read(path, fps)) for label, path in _labelled(demos)]
    if protocol == "closed":
        return [((None, frozenset(), None), motions)]
    known = set(clip_files(repertoire))
    runs = [((label, frozenset(), None), [m for m in motions if m[0] == label])
            for label in sorted({m[0] for m in motions} & known)]
    if not runs:
        raise ConfigError("no demo of a repertoire movement to leave out", file=demos,
                          expected="demo folders named like repertoire movements", available=sorted(known))
    return runs


def _group_runs(profile, repertoire: Path, group: str | None, fps: float | None = None):
    """Leave one group out: the clips of each group as demos of a repertoire of every other group's clips."""
    if not group:
        raise ConfigError("protocol 'groups' needs a pattern", key=("group",),
                          expected="--group REGEX whose first capture group names a clip's group in its file name "
                                   "(a style, a performer), e.g. '_([a-z-]+)_[0-9]+\\.bvh$'")
    try:
        pattern = re.compile(group)
    except re.error as err:
        raise ConfigError(f"not a regular expression: {err}", key=("group",), expected="a Python regular expression "
                          "with one capture group") from None
    if pattern.groups < 1:
        raise ConfigError(f"{group!r} has no capture group", key=("group",),
                          expected="a regular expression whose first capture group is the group's name")
    by_group: dict[str, list[tuple[str, Path]]] = {}
    unmatched = []
    for label, path in _labelled(repertoire):
        found = pattern.search(path.name)
        if found is None or not found.group(1):
            unmatched.append(path.name)
            continue
        by_group.setdefault(found.group(1), []).append((label, path))
    if unmatched:
        raise ConfigError(f"{len(unmatched)} clip names without a group", file=repertoire, key=("group",),
                          expected=f"file names in which {group!r} finds a group", available=unmatched[:10])
    if len(by_group) < 2:
        raise ConfigError(f"{len(by_group)} group found", file=repertoire, key=("group",),
                          expected="at least two groups to leave one out", available=sorted(by_group))
    return [((None, frozenset(p for _, p in items), name), [(label, p, profile.read(p, fps)) for label, p in items])
            for name, items in sorted(by_group.items())]


def _take_runs(profile, repertoire: Path, demos: Path | None, takes: int, fps: float | None = None):
    """The first ``takes`` clips of each movement (by name) as the repertoire; its other clips and the demos as
    demos."""
    if takes < 1:
        raise ConfigError(f"takes:{takes}", key=("protocol",), expected="takes:N with N >= 1")
    left = [(label, path) for label, paths in clip_files(repertoire).items() for path in sorted(paths)[takes:]]
    items = [(label, path, profile.read(path, fps)) for label, path in left]
    if demos is not None:
        items += [(label, path, profile.read(path, fps)) for label, path in _labelled(demos)]
    if not items:
        raise ConfigError(f"no clip to classify with takes:{takes}", file=repertoire,
                          expected=f"movement folders of more than {takes} clips, or --demos DIR")
    return [((None, frozenset(path for _, path in left), None), items)]


@contextmanager
def _repertoire_without(folder: Path, movement: str | None, files: frozenset[Path] = frozenset()):
    """``folder``, or (leaving ``movement`` or ``files`` out) a temporary folder of links to the other clips."""
    if movement is None and not files:
        yield folder
        return
    from toolkit.files import scratch_folder

    with scratch_folder("likeme-left-out-") as tmp:
        for name, clips in clip_files(folder).items():
            kept = [f for f in clips if f not in files]
            if name == movement or not kept:
                continue
            (Path(tmp) / name).mkdir()
            for f in kept:
                (Path(tmp) / name / f.name).symlink_to(f.resolve())
        yield Path(tmp)


BOUNDARY_TOLERANCE = 0.25
"""Seconds within which ``segmentation``'s ``within`` counts a boundary as found where it is."""


def segmentation(pm, profile, streams: Path, segmenters: Sequence[str], *, repertoire: Path | None = None,
                 settings=None, quiet: bool = True, observer: dict[str, Any] | None = None,
                 fps: float | None = None) -> dict[str, Any]:
    """Segment every stream with every segmenter; precision, recall, F1, boundary error and speed.

    ``boundary_error``: the mean absolute difference (frames) of every paired boundary over all the streams;
    ``within``: the share of all the true boundaries found within :data:`BOUNDARY_TOLERANCE` seconds
    (:func:`plugins.bench.metrics.segmentation_scores`)."""
    settings = _with_clip_rate(settings, fps)
    data = [(path, truth, profile.read(path, fps)) for path, truth in _streams(streams)]
    plugins, rows, timelines = [], [], _timelines(data)
    for name in segmenters:
        clock = _Clock(compose_observer(pm, profile, repertoire or streams, segmenter=name, matcher=None,
                                        settings=settings, **(observer or {})), profile)
        found_all = true_all = tp = 0
        errors: list[float] = []
        within = 0.0
        for path, truth, motion in _progress(data, f"segmentation {name}", quiet):
            found = [o.segment for o in clock.run("watch", motion)]
            timelines[path.name]["found"][name] = [[f.start, f.end] for f in found]
            s = segmentation_scores([(f.start, f.end) for f in found], [(a, b) for a, b, _ in truth],
                                    tolerance=BOUNDARY_TOLERANCE * motion.fps)
            found_all, true_all, tp = found_all + s["found"], true_all + s["true"], tp + s["true_positives"]
            errors.extend(s["boundary_errors"])
            within += s["within"] * 2 * s["true"]
            rows.append({"plugin": name, "item": path.name, "found": s["found"], "true": s["true"],
                         "f1": round(s["f1"], 4), "boundary_error": round(s["boundary_error"], 2),
                         "within": round(s["within"], 4)})
        precision = tp / found_all if found_all else 0.0
        recall = tp / true_all if true_all else 0.0
        f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
        plugins.append({"plugin": name, "precision": precision, "recall": recall, "f1": f1,
                        "boundary_error": float(np.mean(errors)) if errors else float("nan"),
                        "within": within / (2 * true_all) if true_all else 1.0, "fps": clock.fps,
                        "items": len(data)})
    return {"benchmark": "segmentation", "plugins": plugins, "items": rows, "timelines": list(timelines.values())}


def _timelines(data) -> dict[str, dict[str, Any]]:
    """Per stream, what its plot draws: its length, its true segments, and (filled in) the segments each plugin
    found (``[start, end]``, end exclusive; with the movement recognised in ``stream``)."""
    return {path.name: {"item": path.name, "frames": motion.n_frames, "fps": motion.fps,
                        "truth": [[a, b, m] for a, b, m in truth], "found": {}} for path, truth, motion in data}


def stream(pm, profile, repertoire: Path, streams: Path, segmenters: Sequence[str], matchers: Sequence[str], *,
           settings=None, quiet: bool = True, observer: dict[str, Any] | None = None,
           fps: float | None = None) -> dict[str, Any]:
    """Segment and recognise every stream with every pairing; the movement error rate."""
    settings = _with_clip_rate(settings, fps)
    data = [(path, truth, profile.read(path, fps)) for path, truth in _streams(streams)]
    plugins, rows, timelines = [], [], _timelines(data)
    for seg in segmenters:
        for mat in matchers:
            clock = _Clock(compose_observer(pm, profile, repertoire, segmenter=seg, matcher=mat, settings=settings,
                                            **(observer or {})), profile)
            errors, true_count = 0.0, 0
            for path, truth, motion in _progress(data, f"stream {seg} + {mat}", quiet):
                observed = clock.run("watch", motion)
                recognised = [o.movement or "unknown" for o in observed]
                timelines[path.name]["found"][f"{seg}+{mat}"] = [[o.segment.start, o.segment.end, m]
                                                                 for o, m in zip(observed, recognised)]
                labels = [label for _, _, label in truth]
                rate = movement_error_rate(recognised, labels)
                errors += rate * len(labels)
                true_count += len(labels)
                rows.append({"plugin": f"{seg}+{mat}", "item": path.name, "truth": " ".join(labels),
                             "recognised": " ".join(recognised), "error_rate": round(rate, 4)})
            plugins.append({"plugin": f"{seg}+{mat}", "segmenter": seg, "matcher": mat,
                            "error_rate": errors / max(true_count, 1), "fps": clock.fps,
                            "items": len(data)})
    return {"benchmark": "stream", "plugins": plugins, "items": rows, "timelines": list(timelines.values())}


COLUMNS = {
    "recognition": [("accuracy", "{:.3f}"), ("known_accuracy", "{:.3f}"), ("rejection", "{:.3f}"),
                    ("macro_f1", "{:.3f}"), ("decision_median", "{:.2f}"),
                    ("decision_p90", "{:.2f}"), ("fps", "{:.0f}"), ("items", "{}")],
    "segmentation": [("precision", "{:.3f}"), ("recall", "{:.3f}"), ("f1", "{:.3f}"), ("boundary_error", "{:.1f}"),
                     ("within", "{:.3f}"), ("fps", "{:.0f}"), ("items", "{}")],
    "stream": [("error_rate", "{:.3f}"), ("fps", "{:.0f}"), ("items", "{}")],
}


def _cell(fmt: str, value: Any) -> str:
    """A table cell; a score that does not apply (NaN: no demo of an unknown movement to reject) is '-'."""
    return "-" if isinstance(value, float) and np.isnan(value) else fmt.format(value)


def table(result: dict[str, Any]) -> str:
    """A markdown table of a result's per-plugin rows."""
    cols = COLUMNS[result["benchmark"]]
    lines = ["| plugin | " + " | ".join(c for c, _ in cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for row in result["plugins"]:
        lines.append(f"| {row['plugin']} | " + " | ".join(_cell(fmt, row[c]) for c, fmt in cols) + " |")
    return "\n".join(lines)


def write_outputs(result: dict[str, Any], args: Any) -> None:
    from toolkit.files import write_output

    result = {**result, "settings": {"seed": getattr(args, "seed", None), "versions": _versions(),
                                     "set": list(getattr(args, "set", []))}}
    if args.json:
        write_output(args.json, json.dumps(result, indent=1, default=float) + "\n")
    if args.csv:
        keys = ["kind", "plugin", "item"] + sorted({k for r in result["plugins"] + result["items"] for k in r}
                                                   - {"plugin", "item", "labels", "confusion"})
        rows = [{"kind": "plugin", **{k: v for k, v in r.items() if k not in ("labels", "confusion")}}
                for r in result["plugins"]] + [{"kind": "item", **r} for r in result["items"]]
        out = io.StringIO()
        writer = csv.DictWriter(out, fieldnames=keys, extrasaction="ignore", lineterminator="\n")
        writer.writeheader()
        for r in rows:
            writer.writerow(r)
        out.write(f"# versions: {json.dumps(result['settings']['versions'])}\n")
        write_output(args.csv, out.getvalue())
    if args.plot:
        plot(result, Path(args.plot))


def plot(result: dict[str, Any], path: Path) -> Path:
    """Draw a result to PNG (:func:`plugins.bench.plots.plot_result`): confusion matrices (recognition), timelines
    of true and found segments per stream (segmentation, stream)."""
    from plugins.bench.plots import plot_result

    return plot_result(result, path)


def cell(spec: dict[str, Any]) -> dict[str, Any]:
    """One benchmark run from plain data, in whichever process runs it (:func:`plugins.bench.jobs.run_items`).

    ``spec``: ``benchmark`` (``recognition``, ``segmentation`` or ``stream``), ``body`` (a profile path),
    ``repertoire``, ``demos``, ``streams`` (folders or None), ``matchers``, ``segmenters`` (names), ``set``
    (``TABLE.KEY=VALUE`` strings), ``observer`` (arguments of :func:`toolkit.observe.compose_observer`),
    ``protocol``, ``group``, ``fps``, ``jitter`` and ``dropout`` (:mod:`plugins.bench.tracker`). The process builds
    its own plugin manager (the installed plugins), profile and observers; the result is that of
    :func:`recognition`, :func:`segmentation` or :func:`stream`.
    """
    from toolkit.manager import create_plugin_manager

    pm = create_plugin_manager()
    profile = jittered(load_profile(spec["body"]), spec.get("jitter") or 0.0, dropout=spec.get("dropout") or 0.0)
    settings, observer, fps = _settings(spec.get("set", ())), dict(spec.get("observer") or {}), spec.get("fps")
    folder = {k: Path(spec[k]) if spec.get(k) else None for k in ("repertoire", "demos", "streams")}
    if spec["benchmark"] == "recognition":
        return recognition(pm, profile, folder["repertoire"], folder["demos"], spec["matchers"], settings=settings,
                           observer=observer, protocol=spec.get("protocol", "closed"), group=spec.get("group"),
                           fps=fps)
    if spec["benchmark"] == "segmentation":
        return segmentation(pm, profile, folder["streams"], spec["segmenters"], repertoire=folder["repertoire"],
                            settings=settings, observer=observer, fps=fps)
    return stream(pm, profile, folder["repertoire"], folder["streams"], spec["segmenters"], spec["matchers"],
                  settings=settings, observer=observer, fps=fps)


def merge(results: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The results of one benchmark run per plugin (:func:`cell`) as one result: plugins and items in order,
    each stream's timeline with every plugin's segments."""
    out = {**results[0], "plugins": [p for r in results for p in r["plugins"]],
           "items": [i for r in results for i in r["items"]]}
    if "timelines" in out:
        timelines = {t["item"]: {**t, "found": {}} for t in results[0]["timelines"]}
        for r in results:
            for t in r["timelines"]:
                timelines[t["item"]]["found"].update(t["found"])
        out["timelines"] = list(timelines.values())
    return out


def _parallel(kind: str, args: Any, observer: dict[str, Any]) -> dict[str, Any]:
    """``--jobs N`` or ``--scheduler ADDRESS``: one :func:`cell` per plugin (per pairing for ``stream``), merged in
    the plugins' order, so the table is the one a single process prints (frames per second aside)."""
    from plugins.bench.jobs import run_items

    spec = {"benchmark": kind, "body": str(args.body), "set": list(args.set), "observer": observer, "fps": args.fps,
            "repertoire": getattr(args, "repertoire", None), "demos": getattr(args, "demos", None),
            "streams": getattr(args, "streams", None), "protocol": getattr(args, "protocol", "closed"),
            "group": getattr(args, "group", None), "jitter": getattr(args, "jitter", 0.0),
            "dropout": getattr(args, "dropout", 0.0)}
    if kind == "recognition":
        specs = [{**spec, "matchers": [m]} for m in args.matcher or MATCHERS]
    elif kind == "segmentation":
        specs = [{**spec, "segmenters": [s]} for s in args.segmenter or SEGMENTERS]
    else:
        specs = [{**spec, "segmenters": [s], "matchers": [m]} for s in args.segmenter or SEGMENTERS[:2]
                 for m in args.matcher or MATCHERS]
    return merge(run_items(cell, specs, jobs=args.jobs, scheduler=args.scheduler))


def run(kind: str, args: Any, pm: Any) -> int:
    """``likeme bench recognition|segmentation|stream``: run the benchmark, print its table, write its outputs."""
    profile = jittered(load_profile(args.body), getattr(args, "jitter", 0.0), dropout=getattr(args, "dropout", 0.0))
    settings = _settings(args.set)
    observer = {"correspondence": args.correspondence,
                "lengths_for_height": "" if args.lengths_for_height is None else args.lengths_for_height,
                "template": args.observer}
    if getattr(args, "jobs", 1) > 1 or getattr(args, "scheduler", None):
        result = _parallel(kind, args, observer)
    elif kind == "recognition":
        result = recognition(pm, profile, Path(args.repertoire), Path(args.demos) if args.demos else None,
                             args.matcher or MATCHERS, settings=settings, quiet=args.quiet, observer=observer,
                             protocol=args.protocol, group=args.group, fps=args.fps)
    elif kind == "segmentation":
        result = segmentation(pm, profile, Path(args.streams), args.segmenter or SEGMENTERS,
                              repertoire=Path(args.repertoire) if args.repertoire else None, settings=settings,
                              quiet=args.quiet, observer=observer, fps=args.fps)
    else:
        result = stream(pm, profile, Path(args.repertoire), Path(args.streams), args.segmenter or SEGMENTERS[:2],
                        args.matcher or MATCHERS, settings=settings, quiet=args.quiet, observer=observer,
                        fps=args.fps)
    print(table(result))
    if kind == "recognition":
        for row in result["plugins"]:
            print(f"\n{row['plugin']} confusion (rows true, columns recognised): {', '.join(row['labels'])}")
            print(text_table([[label, *counts] for label, counts in zip(row["labels"], row["confusion"])],
                             [("", "right")] * (len(row["labels"]) + 1), header=False))
    write_outputs(result, args)
    return 0
