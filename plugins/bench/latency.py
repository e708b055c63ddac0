"""``likeme bench latency``: how long after the segmenter closes a segment ``likeme observe -`` prints it.

A frame-paced producer writes each stream's frames, one CSV line at a time at the stream's frame rate, into
``likeme observe ... -`` running as a tracker's reader would run it; each frame is taken as made when it is due
(``start + k / fps``), as a tracker makes it whether or not the reader has taken the frames before it (a full pipe
delays the writing, not the frame); a reader notes when each segment's line arrives. Which frame closes each
segment (the segmenter's decision) is found by the same observer fed the same frames one at a time in this process
(the observations of ``observe -`` are those of the files, frame for frame: ``tests/toolkit/recordings/
test_live_input.py``). The latency of a segment is the time from the frame that closed it to the arrival of its
line; the time from its last frame is printed beside it (it holds the segmenter's own wait: the
frames it needs to see before it decides).

``--start ready`` (the default) starts the frames when ``observe`` says it is watching (its first line); ``--start
now`` starts them at once, as a tracker that does not wait would: the first segments then also wait for the
observer to be composed and to catch up. Segments closed by the end of the input are left out. Each feeding of a
stream is an item of ``--jobs`` / ``--scheduler`` (:func:`plugins.bench.jobs.run_items`): streams fed at once share
the machine, so the default is one after another. Without
``--streams`` the streams are made here (``likeme bench make-data``) from the project's own characters.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.errors import ConfigError, LikemeError

__all__ = ["cmd_latency", "stream_latencies", "closing_frames"]


def closing_frames(character: Any, profile: Any, motion: Any) -> dict[tuple[int, int], int]:
    """For each segment the observer finds in ``motion`` fed one frame at a time: (start, end) -> the frame whose
    push closed it (segments closed by the end of the input are left out)."""
    from toolkit.observe import Observer

    observer = Observer(character, profile.body, motion.fps)
    closed = {}
    for f in range(motion.n_frames):
        for o in observer.push(motion.positions[f], motion.visible[f]):
            closed[(o.segment.start, o.segment.end)] = f
    return closed


def _csv_lines(path: Path, fps: float) -> tuple[str, list[str]]:
    """A BVH stream's joint positions as a CSV header with a time column and one line per frame."""
    from toolkit.recordings.bvh import read_bvh

    bvh = read_bvh(path)
    positions = bvh.positions()
    header = "time," + ",".join(f"{n}_{a}" for n in bvh.names for a in "xyz")
    rows = [f"{k / fps:.6f}," + ",".join(f"{v:.6g}" for v in frame.ravel()) for k, frame in enumerate(positions)]
    return header, rows


def stream_latencies(command: list[str], path: Path, closed: dict[tuple[int, int], int], fps: float, *,
                     start: str = "ready", timeout: float = 600.0) -> dict[str, Any]:
    """Feed one stream to ``command`` (``likeme observe ... -``) at ``fps``; the latency of every segment it prints
    that ``closed`` knows, after its closing frame and after its last frame (s), and the start-up (s)."""
    header, rows = _csv_lines(path, fps)
    proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            bufsize=0)
    written = np.full(len(rows), np.nan)
    arrived: list[tuple[float, int, int]] = []
    ready = threading.Event()
    spawned = time.perf_counter()
    started: list[float] = []

    def read() -> None:
        for raw in proc.stdout:
            now = time.perf_counter()
            line = raw.decode("utf-8", "replace")
            if not ready.is_set():
                started.append(now)
                ready.set()
            if line.startswith("  frames"):
                a, b = line.split()[1].split("-")
                arrived.append((now, int(a), int(b)))
        ready.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        proc.stdin.write((header + "\n").encode())
        if start == "ready":
            ready.wait(timeout)
        t0 = time.perf_counter()
        for k, row in enumerate(rows):
            written[k] = t0 + k / fps  # when the frame is due: a tracker makes it then, whether the pipe takes it
            delay = written[k] - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            proc.stdin.write((row + "\n").encode())
        proc.stdin.close()
        proc.wait(timeout)
    except (BrokenPipeError, subprocess.TimeoutExpired):
        pass
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    reader.join(timeout)
    err = proc.stderr.read().decode("utf-8", "replace").strip()
    proc.stderr.close()
    if proc.returncode != 0:
        raise LikemeError(f"'{' '.join(command)}' exited with status {proc.returncode} on {path}: {err[-300:]}")
    after_decision, after_end = [], []
    for now, a, b in arrived:
        if (a, b) in closed and np.isfinite(written[closed[(a, b)]]):
            after_decision.append(now - written[closed[(a, b)]])
            after_end.append(now - written[b - 1])
    return {"stream": str(path), "segments": len(after_decision), "after_decision_s": after_decision,
            "after_end_s": after_end, "startup_s": (started[0] - spawned) if started else float("nan")}


def _feed(item: tuple) -> dict[str, Any]:
    """One stream fed once (an item of :func:`plugins.bench.jobs.run_items`)."""
    command, path, closed, fps, start = item
    return stream_latencies(command, Path(path), closed, fps, start=start)


def _percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def cmd_latency(args: argparse.Namespace, pm: Any) -> int:
    from plugins.bench.jobs import run_items
    from plugins.bench.startup import likeme_command
    from toolkit.observe import compose_observer
    from toolkit.recordings.profile import load_profile

    with tempfile.TemporaryDirectory(prefix="likeme-latency-") as tmp:
        if args.streams:
            if not (args.body and args.repertoire):
                raise ConfigError("--streams without --body and --repertoire", key=("--streams",),
                                  expected="--body PROFILE --repertoire DIR with --streams")
            body, repertoire = Path(args.body), Path(args.repertoire)
            streams = sorted(Path(args.streams).glob("*.bvh")) if Path(args.streams).is_dir() else \
                [Path(args.streams)]
            if not streams:
                raise ConfigError("no BVH streams", file=args.streams, expected="a BVH file or a folder of them")
        else:
            from plugins.bench.data import make_data

            data = make_data(pm, Path(tmp) / "data", seed=args.seed, streams=args.n_streams)
            body, repertoire = data / "profile.toml", data / "repertoire"
            streams = sorted((data / "streams").glob("*.bvh"))
        profile = load_profile(body)
        options = [*(["--segmenter", args.segmenter] if args.segmenter else []),
                   *(["--matcher", args.matcher] if args.matcher else [])]
        character = compose_observer(pm, profile, repertoire, segmenter=args.segmenter, matcher=args.matcher or "")
        items = []
        for path in streams:
            motion = profile.read(path)
            fps = args.fps or motion.fps
            closed = closing_frames(character, profile, motion)
            command = [*likeme_command(), "observe", "--body", str(body), "--repertoire", str(repertoire),
                       "--fps", f"{fps:g}", *options, "-"]
            items += [(command, str(path), closed, fps, args.start)] * args.runs
        rows = run_items(_feed, items, jobs=args.jobs, scheduler=args.scheduler)
    decision = [x for r in rows for x in r["after_decision_s"]]
    end = [x for r in rows for x in r["after_end_s"]]
    startup = [r["startup_s"] for r in rows if np.isfinite(r["startup_s"])]
    print(f"likeme observe - fed at the streams' frame rate, frames started {'when it was ready' if args.start == 'ready' else 'at once'}; "
          f"{len(rows)} runs, {len(decision)} segments")
    print(f"{'latency':<26} {'median ms':>10} {'p95 ms':>8} {'max ms':>8}")
    for name, values in (("after the segmenter closed", decision), ("after the segment's end", end)):
        print(f"{name:<26} {_percentile(values, 50) * 1000:10.0f} {_percentile(values, 95) * 1000:8.0f} "
              f"{(max(values) if values else float('nan')) * 1000:8.0f}")
    print(f"{'start-up (spawn to ready)':<26} {statistics.median(startup) * 1000 if startup else float('nan'):10.0f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "median_after_decision_s": _percentile(decision, 50),
                                               "p95_after_decision_s": _percentile(decision, 95)}, indent=1) + "\n")
    return 0
