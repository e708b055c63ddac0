"""``likeme bench memory``: the observer's memory against the length of the stream it watches.

Two measurements, each printed as a table (``docs/benchmarks.md`` keeps the figures with the command):

- *live*: an :class:`~toolkit.observe.Observer` (the observer template's components, a repertoire of Max's movements
  written by :func:`plugins.bench.data.make_data`) is fed Morris performing random movements of that repertoire
  with 3 mm observation noise, at ``--fps`` frames per second, a packet of ``--block`` frames at a time, through
  the motion-capture perception, for ``--minutes`` of stream time. Every ``--every`` simulated minutes it prints
  the resident set (RSS, now and peak), the rows working memory holds and, with ``--tracemalloc``, the peak of
  Python's traced allocations since the last line: memory that is flat in stream length shows as equal lines.
- *observe*: the peak RSS of a ``likeme observe`` subprocess (``/usr/bin/time -v`` when present, else
  ``resource.getrusage(RUSAGE_CHILDREN)``) on generated BVH streams of ``--observe-minutes`` minutes each (the same
  movements, written into a temporary folder), capped at ``--limit`` GB of address space so that a reader that
  needs more fails instead of taking the machine.

The live observer and each ``--observe-minutes`` stream are the items of ``--jobs`` / ``--scheduler``
(:func:`plugins.bench.jobs.run_with_pm`): each is measured inside the process that runs it, on that process's own
copy of the data (:func:`process_data`). Run in this process (the default), each table row is printed as it is
measured; from workers, when they are all back.
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["random_stream", "live_memory", "observe_memory", "write_stream", "process_data", "cmd_memory"]

NOISE = 0.003
"""Observation noise (m) on the generated streams, as ``make-data`` writes its streams."""


def _rss() -> tuple[float, float]:
    """This process's resident set now and its peak (MB), from ``/proc/self/status`` (``getrusage`` elsewhere)."""
    try:
        text = Path("/proc/self/status").read_text()
        now = float(re.search(r"VmRSS:\s+(\d+)", text).group(1)) / 1024
        peak = float(re.search(r"VmHWM:\s+(\d+)", text).group(1)) / 1024
        return now, peak
    except (OSError, AttributeError):
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        return peak, peak


def random_stream(pm: Any, fps: float, *, seed: int = 0, block: int = 120) -> Iterator[np.ndarray]:
    """Blocks of world positions (``block``, P, 3) in Max's parts: Morris performing random movements of Max's
    repertoire at speeds 0.8-1.25 from his rest pose, with 0.2-1 s of standing between them and ``NOISE`` metres of
    noise, forever (the caller stops)."""
    from toolkit import load_character
    from toolkit.config.search import resolve_file

    rng = np.random.default_rng(seed)
    max_c = load_character(resolve_file("max.toml", None, pm), pm)
    morris = load_character(resolve_file("morris.toml", None, pm), pm)
    index = [morris.body.parts.index(p) for p in max_c.body.parts]
    movements = [m for m in max_c.motor.movements() if m in morris.motor.movements() and m != "stand"]
    rest = morris.motor.rest_pose()[index]
    cache: dict[tuple[str, float], np.ndarray] = {}
    pending = np.zeros((0, len(index), 3))
    while True:
        while len(pending) < block:
            name, speed = str(rng.choice(movements)), float(rng.choice([0.8, 1.0, 1.25]))
            if (name, speed) not in cache:
                cache[name, speed] = morris.motor.perform(name, fps=fps, speed=speed).positions[:, index]
            still = np.repeat(rest[None], int(rng.integers(int(0.2 * fps), int(fps) + 1)), axis=0)
            pending = np.concatenate([pending, still, cache[name, speed]])
        out, pending = pending[:block], pending[block:]
        yield out + rng.normal(0.0, NOISE, out.shape)


def _data(pm: Any, folder: Path) -> Path:
    """The repertoire and profile ``make-data`` writes (no streams), in ``folder``."""
    from plugins.bench.data import make_data

    return make_data(pm, folder, seed=0, streams=0)


_DATA: dict[str, Any] = {}
"""This process's data folder (:func:`process_data`) and the temporary folder holding it."""


def process_data(pm: Any) -> Path:
    """The repertoire and profile of :func:`_data` in a temporary folder of this process, made at the first call
    (the same files in every process) and removed when the process exits."""
    if "data" not in _DATA:
        _DATA["tmp"] = tempfile.TemporaryDirectory(prefix="likeme-memory-")
        _DATA["data"] = _data(pm, Path(_DATA["tmp"].name) / "data")
    return _DATA["data"]


def live_memory(pm: Any, data: Path, *, minutes: float, fps: float, every: float, block: int, seed: int = 0,
                trace: bool = False, settings: dict[str, Any] | None = None, segmenter: str | None = None,
                matcher: str | None = None, correspondence: str = "", out: Any = None) -> list[dict]:
    """Feed a live observer ``minutes`` of stream at ``fps`` and print a line every ``every`` minutes (see the
    module; ``segmenter``, ``matcher``, ``correspondence``: plugins replacing the observer template's); returns the
    lines as dicts."""
    from toolkit.observe import Observer, compose_observer
    from toolkit.recordings.profile import load_profile

    out = sys.stdout if out is None else out
    profile = load_profile(data / "profile.toml")
    character = compose_observer(pm, profile, data / "repertoire", settings=settings, segmenter=segmenter,
                                 matcher=matcher or "", correspondence=correspondence)
    observer = Observer(character, profile.body, fps)
    total, step = int(round(minutes * 60 * fps)), max(1, int(round(every * 60 * fps)))
    rows: list[dict] = []
    segments = 0
    fed = 0
    began = time.perf_counter()
    if trace:
        tracemalloc.start()
    # hand-padded, not plugins.bench.text_table: each row is printed as it is measured, minutes apart, not at the end
    print(f"{'minutes':>8} {'frames':>9} {'segments':>8} {'rows held':>9} {'RSS MB':>8} {'peak RSS MB':>11}"
          + (f" {'traced peak MB':>14}" if trace else "") + f" {'wall s':>7}", file=out, flush=True)
    for positions in random_stream(pm, fps, seed=seed, block=block):
        positions = positions[: total - fed]
        segments += len(observer.push_block(positions))
        fed += len(positions)
        if fed % step < len(positions) or fed >= total:
            now, peak = _rss()
            held = observer.memory.n - getattr(observer.memory, "offset", 0)
            line = {"minutes": round(fed / fps / 60, 2), "frames": fed, "segments": segments, "rows_held": held,
                    "rss_mb": round(now, 1), "peak_rss_mb": round(peak, 1),
                    "wall_s": round(time.perf_counter() - began, 1)}
            text = f"{line['minutes']:8.2f} {fed:9d} {segments:8d} {held:9d} {now:8.1f} {peak:11.1f}"
            if trace:
                line["traced_peak_mb"] = round(tracemalloc.get_traced_memory()[1] / 2**20, 1)
                tracemalloc.reset_peak()
                text += f" {line['traced_peak_mb']:14.1f}"
            print(text + f" {line['wall_s']:7.1f}", file=out, flush=True)
            rows.append(line)
        if fed >= total:
            break
    segments += len(observer.flush())
    if trace:
        tracemalloc.stop()
    return rows


def write_stream(pm: Any, path: Path, *, minutes: float, fps: float, seed: int = 0) -> Path:
    """A BVH file of ``minutes`` of :func:`random_stream` at ``fps`` in Max's body (the layout ``make-data``
    writes: the root, every other part its child, position channels)."""
    from toolkit import load_character
    from toolkit.recordings.bvh_writer import from_joint_positions, write_bvh
    from toolkit.config.search import resolve_file

    body = load_character(resolve_file("max.toml", None, pm), pm).body
    root = body.root_index
    order = [root] + [i for i in range(body.n_parts) if i != root]
    total = int(round(minutes * 60 * fps))
    blocks, have = [], 0
    for block in random_stream(pm, fps, seed=seed, block=min(total, int(fps) * 60)):
        blocks.append(block[: total - have])
        have += len(blocks[-1])
        if have >= total:
            break
    positions = np.concatenate(blocks)[:, order]
    write_bvh(from_joint_positions([body.parts[i] for i in order], [-1] + [0] * (len(order) - 1), positions, fps),
              path)
    return path


def _limit(gb: float):
    """A ``preexec_fn`` capping the child's address space at ``gb`` GB."""
    size = int(gb * 2**30)

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (size, size))

    return cap


def observe_memory(data: Path, path: Path, *, limit: float = 4.0, extra: tuple[str, ...] = ()) -> dict[str, Any]:
    """Peak RSS (MB), wall time and exit status of ``likeme observe`` on ``path`` in a subprocess."""
    likeme = shutil.which("likeme") or str(Path(sys.executable).with_name("likeme"))
    command = [likeme, "observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
               "--json", *extra, str(path)]
    timer = "/usr/bin/time"
    began = time.perf_counter()
    if os.access(timer, os.X_OK):
        done = subprocess.run([timer, "-v", *command], capture_output=True, text=True, preexec_fn=_limit(limit))
        found = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
        peak = float(found.group(1)) / 1024 if found else float("nan")
        how = "/usr/bin/time -v"
    else:
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        done = subprocess.run(command, capture_output=True, text=True, preexec_fn=_limit(limit))
        peak = max(before, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024
        how = "getrusage(RUSAGE_CHILDREN)"
    wall = time.perf_counter() - began
    error = next((line for line in done.stderr.splitlines() if line.startswith("likeme: error") or "Error" in line),
                 "")
    return {"file": path.name, "size_mb": round(path.stat().st_size / 2**20, 1), "peak_rss_mb": round(peak, 1),
            "wall_s": round(wall, 1), "status": done.returncode, "error": error, "measured_by": how}


def _memory_item(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """One item of ``likeme bench memory`` in whichever process runs it: the live observer (its table printed here
    when ``item["print"]``, else returned as text) or ``likeme observe`` on one generated stream (its row)."""
    import io

    from toolkit.observe import compose_observer
    from toolkit.recordings.profile import load_profile

    data = process_data(pm)
    if item["what"] == "observe":
        folder = Path(_DATA["tmp"].name)
        path = write_stream(pm, folder / f"stream_{item['minutes']:g}min.bvh", minutes=item["minutes"],
                            fps=item["fps"], seed=item["seed"])
        try:
            return observe_memory(data, path, limit=item["limit"])
        finally:
            path.unlink()
    character = compose_observer(pm, load_profile(data / "profile.toml"), data / "repertoire",
                                 segmenter=item["segmenter"], matcher=item["matcher"] or "",
                                 correspondence=item["correspondence"], settings=item["settings"])
    names = {k: c.name for k, c in character.components().items() if k != "action"}
    head = (f"live observer: {item['minutes']:g} simulated minutes at {item['fps']:g} fps, {item['block']} frames a "
            f"packet; " + ", ".join(f"{k} {v}" for k, v in names.items()) + "\n")
    if item["print"]:
        print(head, end="", flush=True)
    out = None if item["print"] else io.StringIO()
    rows = live_memory(pm, data, minutes=item["minutes"], fps=item["fps"], every=item["every"], block=item["block"],
                       seed=item["seed"], trace=item["trace"], settings=item["settings"], segmenter=item["segmenter"],
                       matcher=item["matcher"], correspondence=item["correspondence"], out=out)
    return {"rows": rows, "names": "" if item["print"] else head, "text": "" if out is None else out.getvalue()}


def cmd_memory(args: Any, pm: Any) -> int:
    """``likeme bench memory``."""
    from plugins.bench.scaling import MAX_FRAMES
    from toolkit.config.settings import parse_settings
    from toolkit.errors import ConfigError

    for value in args.observe_minutes or ():  # each in range already (the option's type); a stream is written whole
        frames = value * 60.0 * args.fps
        if frames > MAX_FRAMES:
            raise ConfigError(f"{value:g} minutes at {args.fps:g} fps are {frames:,.0f} frames",
                              key=("--observe-minutes",),
                              expected=f"at most {MAX_FRAMES:,} frames a stream (minutes x 60 x --fps)")
    from plugins.bench.jobs import in_process, run_with_pm

    here = in_process(args.jobs, args.scheduler)
    settings = parse_settings(list(args.set))
    live = {"what": "live", "minutes": args.minutes, "fps": args.fps, "every": args.every, "block": args.block,
            "seed": args.seed, "trace": args.tracemalloc, "settings": settings, "segmenter": args.segmenter,
            "matcher": args.matcher, "correspondence": args.correspondence, "print": here}
    streams = [{"what": "observe", "minutes": m, "fps": args.fps, "seed": args.seed, "limit": args.limit}
               for m in args.observe_minutes or ()]
    items = ([] if args.no_live else [live]) + streams
    # here, one item at a time and each row printed as it is measured; from workers, every item at once
    batches = [[item] for item in items] if here else [items]
    for batch in batches:
        for item, result in zip(batch, run_with_pm(_memory_item, batch, pm, jobs=args.jobs,
                                                   scheduler=args.scheduler)):
            if item["what"] == "live":
                if not here:
                    print(result["names"] + result["text"], end="", flush=True)
                continue
            if item is streams[0]:
                print(f"\nlikeme observe (a subprocess; address space capped at {args.limit:g} GB)")
                # hand-padded as the live table above: a row as each subprocess ends
                print(f"{'minutes':>8} {'file MB':>8} {'peak RSS MB':>11} {'wall s':>7} {'status':>6}  measured by")
            row = result
            print(f"{item['minutes']:8g} {row['size_mb']:8.1f} {row['peak_rss_mb']:11.1f} {row['wall_s']:7.1f} "
                  f"{row['status']:6d}  {row['measured_by']}" + (f"  ({row['error']})" if row["error"] else ""),
                  flush=True)
    return 0
