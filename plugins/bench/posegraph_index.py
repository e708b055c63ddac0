"""``likeme bench posegraph``: the k nearest poses of a large posegraph, spatial index against the exhaustive scan.

Path search's one whole-graph search (Buchsbaum & Blumberg 2005, §5.2 step 2) finds the k poses nearest to the
observed middle frame by eq. 1. This benchmark builds ``--nodes`` poses of ``--parts`` parts, then for ``--queries``
observed poses times :class:`plugins.lib.pose_index.PoseIndex` and the scan (:func:`plugins.lib.pose_index.
nearest_by_scan`, what path search did on every graph before) and checks that both give the same nodes and
distances in the same order.

The poses: the built-in characters' movements (Max's and Morris's, root-relative, on Max's parts), each *take* one
movement performed at a random speed (0.7 to 1.4) by a body scaled by a random factor (0.9 to 1.1) with a random
offset of each part (2 cm) and ``--noise`` metres of noise per coordinate, sampled at 30 poses per second, as a
motion-capture corpus of many performers is; takes are added until there are ``--nodes`` poses. With ``--parts``
other than the body's, the first parts are kept or random parts added near the root. The queries are fresh takes of
the same movements (a performer not in the graph) with 3 mm of observation noise, every part visible (the case path
search meets nearly always; one more tree per visibility pattern otherwise).

Printed: the build time of the tree, the median and 95th percentile of one query with the index and with the scan
(one core, one query after another), the median CPU time of the index's query (``time.thread_time``: what the
query costs without the time other processes held the core, on a shared machine), the memory the tree adds
(resident set before and after the build; the poses themselves are counted apart) and whether every answer agreed.
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np

from plugins.lib.pose_index import PoseIndex, nearest_by_scan

__all__ = ["cmd_posegraph", "make_poses", "run"]

RATE = 30.0
"""Poses per second of movement."""


def _rss() -> int:
    """The process's resident set now, bytes (``/proc/self/statm``; 0 where there is none)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, AttributeError):
        return 0


def _takes(pm: Any) -> tuple[list[np.ndarray], int]:
    """Each built-in movement once, root-relative on Max's parts at ``RATE``: a list of (frames, P, 3)."""
    from toolkit import load_character

    max_ = load_character("max", pm)
    clips = []
    for name in ("max", "morris"):
        character = max_ if name == "max" else load_character(name, pm)
        for movement in character.motor.movements():
            motion = character.motor.perform(movement, fps=RATE)
            motion = motion.onto(max_.body.parts).root_relative(max_.body.root)
            if motion.visible.all():
                clips.append(np.asarray(motion.positions, dtype=float))
    return clips, max_.body.n_parts


def _fit(poses: np.ndarray, parts: int, extra: np.ndarray) -> np.ndarray:
    """``poses`` (n, P, 3) with ``parts`` parts: the first ones, or more added at ``extra`` offsets."""
    if parts <= poses.shape[1]:
        return poses[:, :parts]
    return np.concatenate([poses, poses[:, :1] + extra[None, : parts - poses.shape[1]]], axis=1)


def make_poses(clips: list[np.ndarray], n: int, parts: int, rng: np.random.Generator, *, noise: float,
               extra: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Takes of the clips until ``n`` poses: (n, parts, 3) and the clip each pose came from (n,)."""
    out, which, total = [], [], 0
    while total < n:
        c = int(rng.integers(len(clips)))
        clip = clips[c]
        speed = rng.uniform(0.7, 1.4)
        t = np.arange(0.0, len(clip) - 1, speed)
        lo = np.floor(t).astype(int)
        frac = (t - lo)[:, None, None]
        take = clip[lo] * (1 - frac) + clip[np.minimum(lo + 1, len(clip) - 1)] * frac
        mean = take.mean(axis=0)  # a performer: body size, and how wide the movement is performed
        take = (mean + (take - mean) * rng.uniform(0.8, 1.2)) * rng.uniform(0.9, 1.1)
        take = take + rng.normal(0, noise, size=take.shape)
        take = _fit(take, parts, extra)
        out.append(take)
        which.append(np.full(len(take), c))
        total += len(take)
    return np.concatenate(out)[:n], np.concatenate(which)[:n]


def run(n: int, *, parts: int | None, k: int, queries: int, noise: float, seed: int, pm: Any,
        scan: bool = True) -> dict[str, Any]:
    """One row of the table: build time, query times, memory and agreement at ``n`` poses."""
    rng = np.random.default_rng(seed)
    clips, body_parts = _takes(pm)
    parts = body_parts if parts is None else parts
    extra = rng.normal(0, 0.3, size=(max(parts - body_parts, 0), 3))
    poses, _ = make_poses(clips, n, parts, rng, noise=noise, extra=extra)
    asked, _ = make_poses(clips, queries * 4, parts, rng, noise=0.003, extra=extra)
    asked = asked[rng.choice(len(asked), size=queries, replace=False)]
    visible = np.ones(parts, dtype=bool)
    before = _rss()
    start = time.perf_counter()
    index = PoseIndex(poses)
    index.tree(visible)
    build = time.perf_counter() - start
    grown = _rss() - before
    # every index query first, then the scan of each (compared): a 264 MB scan between two queries would empty the
    # caches the index works from, which a path search (queries one after another) does not do
    times_index, cpu_index, times_scan, answers, agree = [], [], [], [], 0
    for q in asked:
        c0 = time.thread_time()
        t0 = time.perf_counter()
        answers.append(index.nearest(q, visible, k))
        times_index.append(time.perf_counter() - t0)
        cpu_index.append(time.thread_time() - c0)
    if scan:
        for q, got in zip(asked, answers):
            t0 = time.perf_counter()
            want = nearest_by_scan(poses, q, visible, k)
            times_scan.append(time.perf_counter() - t0)
            agree += bool(np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1]))

    def ms(xs: list[float], q: float) -> float:
        return float(np.percentile(xs, q) * 1e3) if xs else float("nan")

    return {"nodes": n, "parts": parts, "k": k, "queries": queries, "build_s": build,
            "index_ms": ms(times_index, 50), "index_p95_ms": ms(times_index, 95),
            "index_cpu_ms": ms(cpu_index, 50),
            "scan_ms": ms(times_scan, 50), "scan_p95_ms": ms(times_scan, 95),
            "poses_mb": poses.nbytes / 1e6, "tree_mb": grown / 1e6,
            "agree": f"{agree}/{queries}" if scan else "not checked"}


def _item(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """:func:`run` of one ``--nodes`` from its keyword arguments, in whichever process runs it."""
    return run(pm=pm, **item)


HEADER = ("nodes", "parts", "k", "build (s)", "index median (ms)", "index p95 (ms)", "index CPU median (ms)",
          "scan median (ms)",
          "scan p95 (ms)", "poses (MB)", "tree (MB)", "same answers")


def _row(r: dict[str, Any]) -> list[str]:
    return [f"{r['nodes']:,}", str(r["parts"]), str(r["k"]), f"{r['build_s']:.2f}", f"{r['index_ms']:.3f}",
            f"{r['index_p95_ms']:.3f}", f"{r['index_cpu_ms']:.3f}", f"{r['scan_ms']:.1f}", f"{r['scan_p95_ms']:.1f}",
            f"{r['poses_mb']:.0f}", f"{r['tree_mb']:.0f}", r["agree"]]


def cmd_posegraph(args: Any, pm: Any) -> int:
    """``likeme bench posegraph``: print one table row per ``--nodes``."""
    from plugins.bench.command import MAX_NODES
    from plugins.bench.jobs import in_process, run_with_pm
    from toolkit.errors import ConfigError

    parts = args.parts or 11
    for n in args.nodes or []:
        if n * parts > MAX_NODES * 11:
            raise ConfigError(f"{n:,} nodes of {parts} parts are {n * parts:,} joint positions", key=("--nodes",),
                              expected=f"at most {MAX_NODES * 11:,} (--nodes x --parts; {MAX_NODES:,} nodes of 11 "
                                       "parts)")
    print("| " + " | ".join(HEADER) + " |")
    print("|" + "---|" * len(HEADER))
    items = [{"n": n, "parts": args.parts, "k": args.k, "queries": args.queries, "noise": args.noise,
              "seed": args.seed, "scan": not args.no_scan} for n in args.nodes or [100_000]]
    # one --nodes a row, each measured in the process that runs it (--jobs, --scheduler); here, printed as it ends
    batches = [[item] for item in items] if in_process(args.jobs, args.scheduler) else [items]
    rows = []
    for batch in batches:
        for r in run_with_pm(_item, batch, pm, jobs=args.jobs, scheduler=args.scheduler):
            rows.append(r)
            print("| " + " | ".join(_row(r)) + " |", flush=True)
    if args.json:
        import json

        from toolkit.files import write_output

        write_output(args.json, json.dumps(rows, indent=2) + "\n")
    return 0
