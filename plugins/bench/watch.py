"""``likeme bench watch``: an observer watches a demonstrator's random movements (Buchsbaum & Blumberg 2005, §5).

The observer watches the demonstrator perform a long random sequence of movements through its own perception
(with noise, dropouts and occlusion) and the benchmark reports

- segmentation precision, recall, F1 and boundary error of its segmenter against what the demonstrator really
  performed (:mod:`plugins.bench.metrics`);
- recognition accuracy of its matcher on the *true* segments;
- the end-to-end movement error rate of what it recognised while watching;
- frames per second of the whole world (acting, perceiving, segmenting, matching).

``--runs R`` makes R independent runs (a fresh world each; run r with seed ``--seed + r``), the items ``--jobs`` and
``--scheduler`` spread over workers (:func:`plugins.bench.jobs.run_with_pm`); :func:`pool_runs` adds up their
counts, so the figures are the same whatever ran the runs (frames per second aside).
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np

from plugins.bench import progress as progress_bar
from plugins.bench import text_table
from plugins.bench.jobs import in_process, run_with_pm
from plugins.bench.metrics import edit_distance, match_segments, movement_error_rate, segmentation_scores
from toolkit import World, load_character
from toolkit.config.search import merge_tables
from toolkit.config.settings import parse_settings
from toolkit.files import write_output
from toolkit.answers import check_match
from toolkit.watching import call_component

__all__ = ["watch_benchmark", "watch_runs", "pool_runs", "render_watch", "cmd_watch"]


def watch_benchmark(
    pm: Any,
    *,
    observer: str = "max",
    demonstrator: str = "morris",
    movements: int = 200,
    seed: int = 0,
    noise: float = 0.005,
    dropout: float = 0.05,
    occlusion: bool = True,
    progress: bool = False,
    settings: dict[str, Any] | None = None,
    exclude: tuple[str, ...] = ("windmill",),
) -> dict[str, Any]:
    """Run the watch benchmark and return its figures (see the module docstring).

    ``exclude``: demonstrator movements never drawn (by default Morris's windmill, which Max does not have).

    ``settings`` are tables merged over the observer's character (``{"segmenter": {"floor": 0.0}}``).
    """
    _check_arguments(movements=movements, seed=seed, noise=noise, dropout=dropout)
    demo = load_character(demonstrator, pm, override={
        "action": {"plugin": "script", "random": movements, "exclude": ["stand", *exclude], "seed": seed, "pause": 0.5}
    })
    obs_override = {"perception": {"plugin": "synthetic-vision", "noise": noise, "dropout": dropout,
                                   "occlusion": occlusion, "seed": seed + 1}}
    obs = load_character(observer, pm, override=merge_tables(obs_override, settings or {}),
                         override_at=(None, ("--set",)))  # the arguments are checked above: the rest is --set
    obs.action = None  # watch only: the benchmark measures perception, segmentation and recognition
    world = World(fps=30.0, pm=pm)
    world.memory_seconds = None  # every row: each true segment is matched from working memory at the end
    target = world.add_actor(demo, "demonstrator", (0.0, 0.0, 1.6), np.pi)
    watcher = world.add_actor(obs, "observer", (0.0, 0.0, 0.0), 0.0)
    watcher.watch(target)

    limit = int(movements * 4 * world.fps) + 300
    started = time.perf_counter()
    steps = range(limit)
    if progress:
        steps = progress_bar(steps, f"{observer} watches {demonstrator}")
    quiet = 0
    for _ in steps:
        world.step()
        quiet = quiet + 1 if world.all_idle() else 0
        if quiet > world.fps:
            break
    watcher._finish()
    elapsed = time.perf_counter() - started

    truth, labels = [], []
    for frame, request in target.performed:
        n = demo.motor.perform(request.movement, fps=world.fps).n_frames
        truth.append((frame - watcher.watch_start, frame - watcher.watch_start + n))
        labels.append(request.movement)
    found = [(e.data["segment"].start, e.data["segment"].end) for e in world.events_of("segment_found", "observer")]
    seg = segmentation_scores(found, truth)
    claimed = {j for _, j in match_segments(found, truth)}
    missed: dict[str, int] = {}
    for j, label in enumerate(labels):
        if j not in claimed:
            missed[label] = missed.get(label, 0) + 1

    correct = 0
    confusions: dict[str, int] = {}
    for (s, e), label in zip(truth, labels):
        match = check_match(obs, call_component(obs, "matcher", "match", watcher.memory.motion(s, e)), "match")
        got = match.movement or "unknown"
        correct += got == label
        if got != label:
            confusions[f"{label} -> {got}"] = confusions.get(f"{label} -> {got}", 0) + 1
    recognised = [e.data["match"].movement or "unknown" for e in world.events_of("movement_recognised", "observer")]

    return {
        "benchmark": "watch",
        "observer": obs.name,
        "demonstrator": demo.name,
        "components": {k: c.name for k, c in obs.components().items()},
        "movements": len(truth),
        "seed": seed,
        "noise": noise,
        "dropout": dropout,
        "occlusion": occlusion,
        "settings": settings or {},
        "visible_fraction": float(watcher.memory.visible.mean()),
        "visible_part_frames": [int(watcher.memory.visible.sum()), int(watcher.memory.visible.size)],
        "segmentation": seg,
        "recognition_accuracy": correct / max(len(truth), 1),
        "recognised_right": correct,
        "confusions": dict(sorted(confusions.items(), key=lambda kv: -kv[1])),
        "unsegmented": dict(sorted(missed.items(), key=lambda kv: -kv[1])),
        "movement_error_rate": movement_error_rate(recognised, labels),
        "edits": edit_distance(recognised, labels),
        "frames": world.frame,
        "seconds": elapsed,
        "frames_per_second": world.frame / elapsed if elapsed > 0 else float("inf"),
        "real_time_factor": (world.frame / world.fps) / elapsed if elapsed > 0 else float("inf"),
        "python": platform.python_version(),
        "numpy": np.__version__,
    }


def _run(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """One run of :func:`watch_benchmark` from its keyword arguments, in whichever process runs it."""
    return watch_benchmark(pm, **item)


def watch_runs(pm: Any, *, runs: int = 1, seed: int = 0, jobs: int = 1, scheduler: str | None = None,
               progress: bool = False, **options: Any) -> dict[str, Any]:
    """``runs`` independent runs of :func:`watch_benchmark` (run r with seed ``seed + r``; ``options`` its other
    keyword arguments) in ``jobs`` local processes or on the Dask ``scheduler``, pooled by :func:`pool_runs` (one
    run: its own figures)."""
    from toolkit.errors import ConfigError
    from toolkit.scenario import MAX_SEED, check_seed

    check_seed(seed, ("--seed",))
    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1 or seed + runs - 1 > MAX_SEED:
        raise ConfigError(f"invalid value {runs!r}", key=("--runs",),
                          expected=f"an integer >= 1 with --seed + runs - 1 at most {MAX_SEED}")
    _check_arguments(movements=options.get("movements", 200), seed=seed, noise=options.get("noise", 0.005),
                     dropout=options.get("dropout", 0.05))
    bar = progress and runs == 1 and in_process(jobs, scheduler)  # a bar over the frames of the one run here
    items = [{**options, "seed": seed + r, "progress": bar} for r in range(runs)]
    began = time.perf_counter()
    results = run_with_pm(_run, items, pm, jobs=jobs, scheduler=scheduler)
    wall = time.perf_counter() - began
    return results[0] if runs == 1 else {**pool_runs(results), "wall_s": wall, "jobs": jobs, "scheduler": scheduler}


def pool_runs(results: list[dict[str, Any]]) -> dict[str, Any]:
    """The figures of several runs of :func:`watch_benchmark` together: counts added up, rates recomputed from the
    sums (precision from all true positives and found segments, boundary error weighted by true positives, ...)."""
    first = results[0]

    def total(key: str) -> int:
        return sum(r["segmentation"][key] for r in results)

    tp, found, true = total("true_positives"), total("found"), total("true")
    precision = tp / found if found else (1.0 if not true else 0.0)
    recall = tp / true if true else 1.0
    weighted = [(r["segmentation"]["boundary_error"], r["segmentation"]["true_positives"]) for r in results
                if r["segmentation"]["true_positives"]]
    seg = {"precision": precision, "recall": recall,
           "f1": 2 * precision * recall / (precision + recall) if precision + recall else 0.0,
           "true_positives": tp, "found": found, "true": true,
           "boundary_error": sum(e * n for e, n in weighted) / sum(n for _, n in weighted) if weighted else float("nan")}

    def added(key: str) -> dict[str, int]:
        out: dict[str, int] = {}
        for r in results:
            for k, v in r[key].items():
                out[k] = out.get(k, 0) + v
        return dict(sorted(out.items(), key=lambda kv: -kv[1]))

    movements = sum(r["movements"] for r in results)
    seen = [sum(r["visible_part_frames"][i] for r in results) for i in (0, 1)]
    frames, seconds = sum(r["frames"] for r in results), sum(r["seconds"] for r in results)
    fps = 30.0  # the world's frame rate (watch_benchmark)
    return {
        **{k: first[k] for k in ("benchmark", "observer", "demonstrator", "components", "noise", "dropout",
                                 "occlusion", "settings", "python", "numpy")},
        "movements": movements, "seed": first["seed"], "runs": len(results), "seeds": [r["seed"] for r in results],
        "visible_fraction": seen[0] / max(seen[1], 1), "visible_part_frames": seen, "segmentation": seg,
        "recognition_accuracy": sum(r["recognised_right"] for r in results) / max(movements, 1),
        "recognised_right": sum(r["recognised_right"] for r in results),
        "confusions": added("confusions"), "unsegmented": added("unsegmented"),
        "movement_error_rate": sum(r["edits"] for r in results) / max(movements, 1),
        "edits": sum(r["edits"] for r in results),
        "frames": frames, "seconds": seconds,
        "frames_per_second": frames / seconds if seconds > 0 else float("inf"),
        "real_time_factor": (frames / fps) / seconds if seconds > 0 else float("inf"),
        "per_run": [{k: r[k] for k in ("seed", "movements", "segmentation", "recognition_accuracy",
                                       "movement_error_rate", "frames", "seconds")} for r in results],
    }


def _check_arguments(*, movements: int, seed: int, noise: float, dropout: float) -> None:
    """The benchmark's own arguments, each reported under its option (not as a key of the characters they reach)."""
    from plugins.action.script import MAX_RANDOM
    from toolkit.errors import ConfigError
    from toolkit.scenario import check_seed

    check_seed(seed, ("--seed",))
    if isinstance(movements, bool) or not isinstance(movements, int) or not 1 <= movements <= MAX_RANDOM:
        raise ConfigError(f"invalid value {movements!r}", key=("--movements",),
                          expected=f"an integer in [1, {MAX_RANDOM}]")
    for option, value, high, what in (("--noise", noise, 1.0, "metres"), ("--dropout", dropout, 1.0, "a probability")):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= high:
            raise ConfigError(f"invalid value {value!r}", key=(option,), expected=f"{what} in [0, {high:g}]")


def render_watch(r: dict[str, Any]) -> str:
    s = r["segmentation"]
    rows = [
        ("movements performed", f"{r['movements']}"),
        ("parts visible", f"{100 * r['visible_fraction']:.1f}%"),
        ("segmentation precision / recall", f"{s['precision']:.3f} / {s['recall']:.3f}"),
        ("segmentation F1", f"{s['f1']:.3f}"),
        ("boundary error (frames)", f"{s['boundary_error']:.1f}"),
        ("recognition accuracy (true segments)", f"{r['recognition_accuracy']:.3f}"),
        ("movement error rate (end to end)", f"{r['movement_error_rate']:.3f}"),
        ("frames per second (world)", f"{r['frames_per_second']:.0f} ({r['real_time_factor']:.1f}x real time)"),
    ]
    seeds = f"seed {r['seed']}" if r.get("runs", 1) == 1 else f"{r['runs']} runs, seeds {r['seeds'][0]}-{r['seeds'][-1]}"
    head = (f"likeme bench watch: {r['observer']} watches {r['demonstrator']} "
            f"({seeds}, noise {r['noise']} m, dropout {r['dropout']}, occlusion {'on' if r['occlusion'] else 'off'})")
    comps = ", ".join(f"{k} {v}" for k, v in r["components"].items())
    if r["settings"]:
        comps += "; " + ", ".join(f"{t}.{k} = {v!r}" for t, table in r["settings"].items() for k, v in table.items())
    if "wall_s" in r:  # several runs: the wall time of them all, on --jobs processes or the --scheduler's workers
        where = f"--scheduler {r['scheduler']}" if r.get("scheduler") else f"--jobs {r.get('jobs', 1)}"
        rows.append(("wall time, all runs", f"{r['wall_s']:.1f} s ({where})"))
    lines = [head, f"  {comps}", text_table(rows, [("", "left"), ("", "left")], header=False)]
    if r["unsegmented"]:
        lines.append("  movements without a matching segment: " + ", ".join(f"{k} ({v})" for k, v in list(r["unsegmented"].items())[:8]))
    if r["confusions"]:
        lines.append("  most frequent confusions: " + ", ".join(f"{k} ({v})" for k, v in list(r["confusions"].items())[:6]))
    return "\n".join(lines)


def cmd_watch(args: argparse.Namespace, pm: Any) -> int:
    result = watch_runs(
        pm, observer=args.observer, demonstrator=args.demonstrator, movements=args.movements, seed=args.seed,
        noise=args.noise, dropout=args.dropout, occlusion=not args.no_occlusion, progress=not args.quiet,
        settings=parse_settings(args.set), runs=args.runs, jobs=args.jobs, scheduler=args.scheduler,
    )
    print(render_watch(result))
    if args.json:
        write_output(args.json, json.dumps(result, indent=2, default=float) + "\n")
    return 0
