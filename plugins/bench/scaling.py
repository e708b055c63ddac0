"""``likeme bench scaling``: how the observer's cost grows with the work (issue 22).

Three axes, each printed as a table with the fitted log-log slope of cost against size (:func:`loglog_slope`:
1.0 is linear, 0 is flat, 2 quadratic):

- *stream length*: an :class:`~toolkit.observe.Observer` (the observer template's components, or ``--segmenter``
  / ``--matcher``; the repertoire of Max's movements :func:`plugins.bench.data.make_data` writes) fed 1, 10 and 60
  minutes of Morris's random movements (:func:`plugins.bench.memory.random_stream`) at ``--fps``; only the
  observer's ``push_block`` and ``flush`` are timed (not the making of the stream), after ``WARM_UP`` seconds fed
  to a throwaway observer. Linear: seconds per minute of stream stay equal.
- *repertoire size*: repertoires of 5, 50 and 500 movements built in memory
  (:func:`plugins.lib.clip_repertoire.clip_repertoire`, then :func:`~toolkit.observe.compose_observer`, which
  builds the motor system's graph or models) from generated clips: the built-in characters' movements at random
  speeds, each renamed and perturbed (a smooth random offset of every part that vanishes at the clip's ends, so the
  ends still meet at the hubs). The build is timed per clip frame; then a fixed set of demos (Morris's versions of
  the movements) is classified against each repertoire, timed per query (the fastest of ``BUILDS`` builds; the mean
  query after one untimed).
- *graph size*: the posegraph's nodes of those repertoires against the time of one ``path-search`` query (the
  observer template's path search, whatever ``--matcher`` is).

``--quick`` uses small sizes (a test); ``--json FILE`` writes every figure.
"""

from __future__ import annotations

import json
import re
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

__all__ = ["loglog_slope", "generated_clips", "stream_axis", "repertoire_axis", "cmd_scaling", "SIZES", "QUICK"]

MAX_FRAMES = 1_000_000
"""The most frames a generated stream has (``--minutes`` x 60 x ``--fps``): it is generated and written whole, about
0.3 GB of positions at a million frames of 11 parts (60 minutes at 30 fps are 108,000)."""
SIZES = {"minutes": (1.0, 10.0, 60.0), "movements": (5, 50, 500)}
"""The sizes of a full run: stream minutes and repertoire movements."""
QUICK = {"minutes": (0.05, 0.1, 0.2), "movements": (3, 6, 12)}
"""The sizes of ``--quick``."""
BUILDS = 3
"""Each repertoire is built this many times and the fastest build reported (the others are the machine's noise)."""
WARM_UP = 10.0
"""Seconds of stream fed to a throwaway observer before the timed ones."""
PERTURB = 0.03
"""Standard deviation (m) of a generated clip's smooth per-part offset at its middle."""


def loglog_slope(sizes: Sequence[float], costs: Sequence[float]) -> float:
    """The slope of ``log(cost)`` against ``log(size)`` fitted by least squares (``numpy.polyfit``, degree 1): the
    exponent b of cost ~ a * size**b. NaN with fewer than two positive, finite points."""
    x, y = np.asarray(sizes, dtype=float), np.asarray(costs, dtype=float)
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if keep.sum() < 2 or len(np.unique(x[keep])) < 2:
        return float("nan")
    return float(np.polyfit(np.log(x[keep]), np.log(y[keep]), 1)[0])


def _characters(pm: Any):
    from toolkit import load_character
    from toolkit.config.search import resolve_file

    max_c = load_character(resolve_file("max.toml", None, pm), pm)
    morris = load_character(resolve_file("morris.toml", None, pm), pm)
    return max_c, morris


def generated_clips(pm: Any, n: int, *, fps: float = 30.0, seed: int = 0) -> tuple[list[Any], list[str]]:
    """``n`` labelled clips (world positions in Max's parts) for a repertoire of ``n`` movements: Max's movements
    in turn at speeds 0.8-1.25, the k-th use of a movement named ``NAME-k`` and perturbed by a smooth random offset
    of every part (``PERTURB`` m at the middle, none at the ends)."""
    from toolkit.motion import Motion

    rng = np.random.default_rng(seed)
    max_c, _ = _characters(pm)
    base = [m for m in max_c.motor.movements() if m != "stand"]
    cache: dict[tuple[str, float], np.ndarray] = {}
    motions, labels = [], []
    for i in range(n):
        name, speed = base[i % len(base)], float(rng.choice([0.8, 1.0, 1.25]))
        if (name, speed) not in cache:
            cache[name, speed] = max_c.motor.perform(name, fps=fps, speed=speed).positions
        positions = cache[name, speed]
        envelope = np.sin(np.linspace(0.0, np.pi, len(positions)))[:, None, None]
        offset = rng.normal(0.0, PERTURB, (1, positions.shape[1], 3))
        offset[:, max_c.body.root_index] = 0.0
        motions.append(Motion(positions + envelope * offset, fps, max_c.body.parts))
        labels.append(name if i < len(base) else f"{name}-{i // len(base)}")
    return motions, labels


def _demos(pm: Any, fps: float) -> list[tuple[str, Any]]:
    """Morris's versions of Max's movements at speed 1 in Max's parts: the fixed queries."""
    from toolkit.motion import Motion

    max_c, morris = _characters(pm)
    index = [morris.body.parts.index(p) for p in max_c.body.parts]
    rng = np.random.default_rng(1)
    out = []
    for m in max_c.motor.movements():
        if m == "stand" or m not in morris.motor.movements():
            continue
        positions = morris.motor.perform(m, fps=fps).positions[:, index]
        out.append((m, Motion(positions + rng.normal(0.0, 0.003, positions.shape), fps, max_c.body.parts)))
    return out


def _names(character: Any) -> str:
    return ", ".join(f"{k} {c.name}" for k, c in character.components().items() if k in ("segmenter", "matcher"))


def stream_axis(pm: Any, data: Path, minutes: Sequence[float], *, fps: float, seed: int = 0,
                segmenter: str | None = None, matcher: str | None = None, block: int = 120,
                settings: dict[str, Any] | None = None) -> tuple[list[dict], str]:
    """Seconds of observing per minute of stream for each length in ``minutes`` (a fresh observer each)."""
    from plugins.bench.memory import random_stream
    from toolkit.observe import Observer, compose_observer
    from toolkit.recordings.profile import load_profile

    profile = load_profile(data / "profile.toml")
    character = compose_observer(pm, profile, data / "repertoire", segmenter=segmenter, matcher=matcher or "",
                                 settings=settings)
    warm = Observer(character, profile.body, fps)  # first calls (lazy imports, caches) left out of the timing
    for positions in random_stream(pm, fps, seed=seed + 1, block=block):
        warm.push_block(positions)
        if warm.n_frames >= WARM_UP * fps:
            break
    warm.flush()
    rows = []
    for length in minutes:
        observer = Observer(character, profile.body, fps)
        total, fed, segments, spent = int(round(length * 60 * fps)), 0, 0, 0.0
        for positions in random_stream(pm, fps, seed=seed, block=block):
            positions = positions[: total - fed]
            began = time.perf_counter()
            segments += len(observer.push_block(positions))
            spent += time.perf_counter() - began
            fed += len(positions)
            if fed >= total:
                break
        began = time.perf_counter()
        segments += len(observer.flush())
        spent += time.perf_counter() - began
        rows.append({"minutes": length, "frames": fed, "segments": segments, "seconds": spent,
                     "s_per_minute": spent / length, "frames_per_s": fed / spent if spent else float("inf")})
    return rows, _names(character)


def repertoire_axis(pm: Any, profile: Any, movements: Sequence[int], *, fps: float, seed: int = 0,
                    segmenter: str | None = None, matcher: str | None = None,
                    settings: dict[str, Any] | None = None) -> tuple[list[dict], str]:
    """Build time per clip frame and query time for repertoires of each size in ``movements``; each row also has
    the posegraph's nodes and a ``path-search`` query time (the graph axis: the same observer when its matcher is
    path search, else the template's path search without ``settings``)."""
    from plugins.lib.clip_repertoire import clip_repertoire
    from toolkit.observe import Observer, compose_observer

    demos = _demos(pm, fps)
    rows, names = [], ""
    for n in movements:
        motions, labels = generated_clips(pm, n, fps=fps, seed=seed)
        frames = sum(m.n_frames for m in motions)
        build = float("inf")
        for _ in range(BUILDS):
            began = time.perf_counter()
            repertoire = clip_repertoire(motions, labels, profile)
            character = compose_observer(pm, profile, repertoire, segmenter=segmenter, matcher=matcher or "",
                                         settings=settings)
            build = min(build, time.perf_counter() - began)
        names = _names(character)
        query, right = _queries(Observer(character, profile.body, fps), demos)
        if character.matcher.name == "path-search":
            graph, search = character, query
        else:
            graph = compose_observer(pm, profile, repertoire, segmenter=segmenter, matcher="path-search")
            search, _ = _queries(Observer(graph, profile.body, fps), demos)
        nodes = len(graph.motor.node_root_relative) if hasattr(graph.motor, "node_root_relative") else 0
        rows.append({"movements": n, "clip_frames": frames, "build_s": build,
                     "build_us_per_frame": 1e6 * build / frames,
                     "query_ms": 1e3 * query, "right": right, "queries": len(demos), "nodes": nodes,
                     "path_search_ms": 1e3 * search})
    return rows, names


def _queries(observer: Any, demos: list[tuple[str, Any]]) -> tuple[float, int]:
    """Mean seconds per ``classify`` over the demos (after one untimed warm-up), and how many came out right (a
    movement ``NAME-k`` counts as ``NAME``)."""
    observer.classify(demos[0][1])
    right, began = 0, time.perf_counter()
    for truth, motion in demos:
        answer = observer.classify(motion).movement or ""
        right += re.sub(r"-\d+$", "", answer) == truth
    return (time.perf_counter() - began) / len(demos), right


def _table(title: str, rows: list[list[Any]], columns: list[str], slope: float, what: str) -> str:
    from plugins.bench import text_table

    return (f"{title}\n" + text_table(rows, [(c, "right") for c in columns])
            + f"\n  log-log slope of {what}: {slope:.2f} (1.0 = linear)\n")


def _axis_item(item: dict[str, Any], pm: Any) -> tuple[list[dict], str]:
    """One size of one axis (``item["axis"]``: ``stream`` minutes or ``repertoire`` movements) in whichever process
    runs it, on the data folder of that process (:func:`plugins.bench.memory.process_data`, the same files
    everywhere)."""
    from plugins.bench.memory import process_data
    from toolkit.recordings.profile import load_profile

    data, options = process_data(pm), {k: item[k] for k in ("fps", "seed", "segmenter", "matcher", "settings")}
    if item["axis"] == "stream":
        return stream_axis(pm, data, [item["size"]], **options)
    return repertoire_axis(pm, load_profile(data / "profile.toml"), [item["size"]], **options)


def cmd_scaling(args: Any, pm: Any) -> int:
    """``likeme bench scaling``."""
    from plugins.bench.jobs import run_with_pm
    from toolkit.errors import ConfigError
    from toolkit.config.settings import parse_settings

    sizes = QUICK if args.quick else SIZES
    minutes = args.minutes or sizes["minutes"]
    movements = args.movements or sizes["movements"]
    for value in minutes:  # each in range already (the option's type); the stream is generated whole
        frames = value * 60.0 * args.fps
        if frames > MAX_FRAMES:
            raise ConfigError(f"{value:g} minutes at {args.fps:g} fps are {frames:,.0f} frames", key=("--minutes",),
                              expected=f"at most {MAX_FRAMES:,} frames a stream (minutes x 60 x --fps)")
    settings = parse_settings(list(args.settings))
    out: dict[str, Any] = {"fps": args.fps, "quick": bool(args.quick), "settings": list(args.settings)}
    given = "".join(f"; --set {text}" for text in args.settings)
    # one item per stream length and per repertoire size, each measured in the process that runs it
    common = {"fps": args.fps, "seed": args.seed, "segmenter": args.segmenter, "matcher": args.matcher,
              "settings": settings}
    items = [{"axis": "stream", "size": m, **common} for m in minutes]
    items += [{"axis": "repertoire", "size": n, **common} for n in movements]
    done = run_with_pm(_axis_item, items, pm, jobs=args.jobs, scheduler=args.scheduler)
    stream, names = [r for d in done[:len(minutes)] for r in d[0]], done[0][1]
    slope = loglog_slope([r["frames"] for r in stream], [r["seconds"] for r in stream])
    out["stream"] = {"observer": names, "rows": stream, "slope": slope}
    print(_table(f"stream length ({names}{given}; {args.fps:g} fps)",
                 [[f"{r['minutes']:g}", r["frames"], r["segments"], f"{r['seconds']:.2f}",
                   f"{r['s_per_minute']:.3f}", f"{r['frames_per_s']:,.0f}"] for r in stream],
                 ["minutes", "frames", "segments", "observe s", "s per minute", "frames/s"], slope,
                 "observe seconds against frames"), flush=True)
    rep, names = [r for d in done[len(minutes):] for r in d[0]], done[len(minutes)][1]
    build_slope = loglog_slope([r["clip_frames"] for r in rep], [r["build_s"] for r in rep])
    query_slope = loglog_slope([r["movements"] for r in rep], [r["query_ms"] for r in rep])
    out["repertoire"] = {"observer": names, "rows": rep, "build_slope": build_slope, "query_slope": query_slope}
    print(_table(f"repertoire size ({names}{given}; {rep[0]['queries']} demo queries)",
                 [[r["movements"], r["clip_frames"], f"{r['build_s']:.2f}", f"{r['build_us_per_frame']:.0f}",
                   f"{r['query_ms']:.2f}", f"{r['right']}/{r['queries']}"] for r in rep],
                 ["movements", "clip frames", "build s", "build us/frame", "query ms", "right"], build_slope,
                 "build seconds against clip frames")
          + f"  log-log slope of query ms against movements: {query_slope:.2f} (0 = independent)\n", flush=True)
    graph_slope = loglog_slope([r["nodes"] for r in rep], [r["path_search_ms"] for r in rep])
    out["graph"] = {"rows": [{k: r[k] for k in ("movements", "nodes", "path_search_ms")} for r in rep],
                    "slope": graph_slope}
    print(_table("graph size (posegraph, path-search)",
                 [[r["nodes"], r["movements"], f"{r['path_search_ms']:.2f}"] for r in rep],
                 ["nodes", "movements", "query ms"], graph_slope, "query ms against nodes"), flush=True)
    if args.json:
        from toolkit.files import write_output

        write_output(args.json, json.dumps(out, indent=1) + "\n")
    return 0
