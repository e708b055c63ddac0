"""``likeme bench facilitation``: Max learns Moritz's movements and imitates familiar ones early (Kopp & Graeser 2006, §4-5).

Max starts with hub nodes only, learns random arm and finger movements by watching them once, then watches more
demonstrations (known ones, some at other speeds, and new ones) with observation noise; the benchmark reports
recognition, how early he commits (response facilitation), false commits, what he learns and how well he imitates.

``--runs R``: R independent runs (a fresh Max each; run r with seed ``--seed + r``), the items ``--jobs`` and
``--scheduler`` spread over workers (:func:`plugins.bench.jobs.run_with_pm`); the figures are computed from every
run's demonstrations together, the same whatever ran them (frames per second aside).
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
from toolkit import World, load_character
from toolkit.files import write_output

__all__ = ["facilitation_benchmark", "facilitation_runs", "render_facilitation", "cmd_facilitation"]


class _Replay:
    """A demonstrator's motor system that plays given motions (random guiding-stroke movements)."""

    def __init__(self, rest: np.ndarray, parts: tuple[str, ...]) -> None:
        self.name = "replay"
        self.rest = rest
        self.parts = parts
        self.motions: dict[str, Any] = {}

    def movements(self) -> list[str]:
        return list(self.motions)

    def rest_pose(self) -> np.ndarray:
        return self.rest

    def perform(self, movement: str, *, speed: float = 1.0, fps: float = 30.0) -> Any:
        return self.motions[movement]


def _random_arm_movement(rng: np.random.Generator, rest: np.ndarray, body: Any, fps: float, *, speed: float = 1.0,
                         strokes_out: list | None = None) -> tuple[Any, list]:
    """Out (one or two guiding strokes of the left wrist), hold, back to rest; elbows by IK. Returns (motion, strokes)."""
    from plugins.lib.guiding_stroke import SHAPES, GuidingStroke
    from plugins.motor.motor_command_graph import place_elbows
    from toolkit import Motion

    w, e, s = body.index("left_wrist"), body.index("left_elbow"), body.index("left_shoulder")
    if strokes_out is None:
        strokes_out, p = [], rest[w].copy()
        count = int(rng.integers(1, 3))
        for k in range(count):
            target = rest[s] + rng.uniform([-0.05, -0.25, 0.15], [0.35, 0.1, 0.45])
            shape = SHAPES[int(rng.integers(0, 5))]
            flow = 0.4 if k < count - 1 else 0.0  # strokes of one movement flow into each other (K&G §3)
            strokes_out.append(GuidingStroke(p, target, rng.uniform(0.5, 0.9), rng.uniform(0.4, 0.6), flow, shape,
                                             rng.normal(size=3), 0.0 if shape == "linear" else rng.uniform(0.2, 0.6)))
            p = target
    back = GuidingStroke(strokes_out[-1].target, rest[w], 0.8)
    path = [st.retimed(st.duration / speed).trajectory(fps)[:-1] for st in strokes_out]
    hold = np.repeat(strokes_out[-1].target[None], int(0.6 * fps), axis=0)
    wrist = np.concatenate([*path, hold, back.trajectory(fps)])
    frames = np.repeat(rest[None], len(wrist), axis=0)
    frames[:, w] = wrist
    upper = float(np.linalg.norm(rest[e] - rest[s]))
    fore = float(np.linalg.norm(rest[w] - rest[e]))
    frames[:, e] = place_elbows(frames[:, s], wrist, upper, fore, np.array([1.0, 0.0, 0.0]))
    return Motion(frames, fps, body.parts), strokes_out


def _random_hand_movement(rng: np.random.Generator, rest: np.ndarray, body: Any, fps: float, *, speed: float = 1.0,
                          transitions_out: list | None = None) -> tuple[Any, list]:
    """Out (one transition, or two through a via posture, of the left hand's fingers), hold, back to rest.

    Returns (motion, the out key postures as hand transitions, one per finger)."""
    from plugins.lib.hand_transition import HandTransition
    from toolkit import Motion

    idx = body.indices(body.hands["left_hand"].fingers)
    if transitions_out is None:
        count = int(rng.integers(1, 3))
        low, high = np.radians([0.0, 0.0, -20.0]), np.radians([90.0, 100.0, 30.0])
        keys = [rest[idx], *(rng.uniform(low, high, size=(len(idx), 3)) for _ in range(count))]
        times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.4, 0.8, count))])
        peak = float(rng.uniform(0.4, 0.6))
        transitions_out = [HandTransition(np.stack([k[j] for k in keys]), times, peak) for j in range(len(idx))]
    # Moritz plays the key postures as a key-frame animation (the monotone cubic through the keys, at constant pace):
    # the fingers do not all stop at a via posture, so it stays one movement for the sensory memory
    t = np.arange(int(round(transitions_out[0].duration / speed * fps))) / fps * speed
    out = [tr.curve(t) for tr in transitions_out]  # (n, 3) per finger
    back = [HandTransition(np.stack([t.target, rest[i]]), np.array([0.0, 0.6])).trajectory(fps) for t, i in zip(transitions_out, idx)]
    hold = int(0.6 * fps)
    fingers = np.stack([np.concatenate([o, np.repeat(t.target[None], hold, axis=0), b])
                        for o, t, b in zip(out, transitions_out, back)], axis=1)
    frames = np.repeat(rest[None], len(fingers), axis=0)
    frames[:, idx] = fingers
    return Motion(frames, fps, body.parts), transitions_out


def _shape_error(a: np.ndarray, b: np.ndarray, n: int = 50) -> float:
    """Mean distance (m) between two paths resampled at ``n`` points equally spaced along each."""
    def resample(p: np.ndarray) -> np.ndarray:
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        u = np.linspace(0.0, arc[-1], n)
        return np.stack([np.interp(u, arc, p[:, d]) for d in range(3)], axis=1)

    return float(np.linalg.norm(resample(a) - resample(b), axis=1).mean())


def facilitation_benchmark(pm: Any, *, demonstrations: int = 200, repertoire: int = 6, seed: int = 0, noise: float = 0.002,
                           novel: float = 0.3, hands: float = 0.3, angle_noise: float = 0.005,
                           progress: bool = False) -> dict[str, Any]:
    """Max learns ``repertoire`` random arm movements (and as many finger movements of the left hand when ``hands``)
    by watching, then watches ``demonstrations`` more (known ones, some at other speeds, and novel ones; a share
    ``hands`` of them finger movements) with observation noise (``noise`` metres on positions, ``angle_noise``
    radians on finger joint angles); see ``docs/benchmarks.md``. The wrist figures are at the top level, the hand
    figures under ``"hand"``."""
    rng = np.random.default_rng(seed)
    moritz = load_character("moritz", pm, override={"action": {"plugin": "script", "movements": []}})
    learner = load_character("max_learner", pm)
    world = World(fps=30.0, pm=pm)
    demo = world.add_actor(moritz, "moritz", (0.0, 0.0, 2.0), np.pi)
    watcher = world.add_actor(learner, "max", (0.0, 0.0, 0.0), 0.0)
    replay = _Replay(moritz.motor.rest_pose(), moritz.body.parts)
    moritz.motor = replay  # type: ignore[assignment]
    moritz.action = None
    watcher.watch(demo)
    fps = world.fps
    points = ~moritz.body.angle_mask
    known: list[tuple[str, list]] = []

    def show(name: str, motion: Any) -> list[list[Any]]:
        """Demonstrate one movement; returns, per segment Max found, the recognitions that belong to it (in order)."""
        from toolkit import Motion, MovementRequest

        noisy = motion.positions.copy()
        if noise:  # metres of noise on the positions
            noisy[:, points] += rng.normal(0.0, noise, noisy[:, points].shape)
        if angle_noise:  # radians on the fingers' joint angles
            noisy[:, ~points] += rng.normal(0.0, angle_noise, noisy[:, ~points].shape)
        replay.motions[name] = Motion(noisy, fps, motion.parts)
        first = len(world.events)
        demo.request(MovementRequest(name))
        limit = world.frame + int(60 * fps)
        while (not demo.idle or not watcher.idle) and world.frame < limit:
            world.step()
        for _ in range(int(0.6 * fps)):
            world.step()
        # a recognition made at a segment's end carries its segment; an early one belongs to the next segment found
        mine = [e for e in world.events[first:] if e.actor == "max"]
        segments = [e.data["segment"] for e in mine if e.kind == "segment_found"]
        groups: list[list[Any]] = [[] for _ in segments]
        for k, e in enumerate(mine):
            if e.kind != "movement_recognised":
                continue
            seg = e.data["segment"]
            if seg is None:
                seg = next((x.data["segment"] for x in mine[k:] if x.kind == "segment_found"), None)
            if seg in segments:
                groups[segments.index(seg)].append(e)
        return groups

    makers = {"wrist": _random_arm_movement, "hand": _random_hand_movement}
    subsystem = {"wrist": "left_wrist", "hand": "left_hand"}
    known_by: dict[str, list[tuple[str, list]]] = {"wrist": known, "hand": []}
    for kind in ("wrist", "hand") if hands > 0 else ("wrist",):
        for i in range(repertoire):
            motion, strokes = makers[kind](rng, replay.rest, moritz.body, fps)
            groups = show(f"teach-{kind}-{i}", motion)
            final = groups[0][-1].data["match"] if groups else None
            if final is not None and final.path:
                known_by[kind].append((final.path[0], strokes))
    rows = []
    jobs = range(demonstrations)
    if progress:
        jobs = progress_bar(jobs, "demonstrations")
    started = time.perf_counter()
    frames_before = world.frame
    for i in jobs:
        kind = "hand" if hands > 0 and rng.random() < hands and known_by["hand"] else "wrist"
        is_novel = bool(rng.random() < novel)
        speed = float(rng.choice([1.0, 1.0, rng.uniform(0.6, 1.6)]))
        if is_novel:
            motion, strokes = makers[kind](rng, replay.rest, moritz.body, fps, speed=speed)
            truth = None
        else:
            truth, strokes = known_by[kind][int(rng.integers(len(known_by[kind])))]
            motion, _ = makers[kind](rng, replay.rest, moritz.body, fps, speed=speed, **{
                "strokes_out" if kind == "wrist" else "transitions_out": strokes})
        graph = learner.motor.graphs[subsystem[kind]]
        edges_before = graph.number_of_edges()
        segments_before = len(world.events_of("segment_found", "max"))
        groups = show(f"demo-{i}", motion)
        segs = world.events_of("segment_found", "max")[segments_before:]
        out = groups[0] if groups else []
        early = next((e.data["match"] for e in out if e.data["segment"] is None), None)
        final = out[-1].data["match"] if out else None
        answer = final.path[0] if final is not None and final.path else (final.movement if final else None)
        seg = segs[0].data["segment"] if segs else None
        learned_out = bool(final is not None and final.details.get("learned"))
        imitation_error = None
        if final is not None and final.path and kind == "wrist":
            executed = np.concatenate([st.trajectory(fps) for e in final.path for st in learner.motor.edge(e).commands])
            shown = np.concatenate([st.trajectory(fps) for st in strokes])
            imitation_error = _shape_error(executed, shown)
        elif final is not None and final.path and learner.motor.edge(final.path[0]).subsystem == "left_hand":
            # per finger, the path of its joint angles (radians) along the commands performed against the one shown
            executed = [np.concatenate([learner.motor.edge(e).commands[j].trajectory(fps) for e in final.path])
                        for j in range(len(strokes))]
            grid = np.linspace(0.0, strokes[0].duration, 100)
            imitation_error = float(np.mean([_shape_error(x, t.curve(grid)) for x, t in zip(executed, strokes)]))
        recognised = early if early is not None else final
        measured = recognised.details.get("speed") if recognised is not None else None
        rows.append({
            "kind": kind,
            "novel": is_novel,
            "speed": speed,
            "measured_speed": None if measured is None else float(measured),
            "truth": truth,
            "answer": answer,
            "imitation_error": imitation_error,
            "committed": early is not None,
            "fraction": (early.decided_at / seg.n_frames) if early is not None and seg is not None and early.decided_at else None,
            "correct": (not is_novel) and not learned_out and answer == truth,
            "false_commit": early is not None and (is_novel or (early.path[0] if early.path else early.movement) != truth),
            "edges_learned": graph.number_of_edges() - edges_before,
            "strokes": len(strokes) if kind == "wrist" else 1,  # a hand movement is one edge, via postures and all
        })
    elapsed = time.perf_counter() - started
    figures = _facilitation_figures([r for r in rows if r["kind"] == "wrist"])
    return {
        "benchmark": "facilitation", "seed": seed, "demonstrations": demonstrations, "repertoire": repertoire, "noise": noise,
        "angle_noise": angle_noise, "hands": hands, **figures,
        "hand": _facilitation_figures([r for r in rows if r["kind"] == "hand"]),
        "frames_per_second": (world.frame - frames_before) / elapsed if elapsed > 0 else float("inf"),
        "frames": world.frame - frames_before, "seconds": elapsed,
        "rows": rows, "python": platform.python_version(), "numpy": np.__version__,
    }


def _run(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """One run of :func:`facilitation_benchmark` from its keyword arguments, in whichever process runs it."""
    return facilitation_benchmark(pm, **item)


def facilitation_runs(pm: Any, *, runs: int = 1, seed: int = 0, jobs: int = 1, scheduler: str | None = None,
                      progress: bool = False, **options: Any) -> dict[str, Any]:
    """``runs`` independent runs of :func:`facilitation_benchmark` (run r with seed ``seed + r``; ``options`` its
    other keyword arguments) in ``jobs`` local processes or on the Dask ``scheduler``; one run: its own result,
    several: the figures of all their demonstrations together (``rows`` with the run of each)."""
    from plugins.bench.jobs import in_process, run_with_pm
    from toolkit.errors import ConfigError
    from toolkit.scenario import MAX_SEED, check_seed

    check_seed(seed, ("--seed",))
    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1 or seed + runs - 1 > MAX_SEED:
        raise ConfigError(f"invalid value {runs!r}", key=("--runs",),
                          expected=f"an integer >= 1 with --seed + runs - 1 at most {MAX_SEED}")
    bar = progress and runs == 1 and in_process(jobs, scheduler)  # a bar over the demonstrations of the one run here
    began = time.perf_counter()
    results = run_with_pm(_run, [{**options, "seed": seed + r, "progress": bar} for r in range(runs)], pm,
                          jobs=jobs, scheduler=scheduler)
    wall = time.perf_counter() - began
    if runs == 1:
        return results[0]
    rows = [{"run": r, **row} for r, result in enumerate(results) for row in result["rows"]]
    frames, seconds = sum(r["frames"] for r in results), sum(r["seconds"] for r in results)
    first = results[0]
    return {
        **{k: first[k] for k in ("benchmark", "seed", "repertoire", "noise", "angle_noise", "hands", "python",
                                 "numpy")},
        "demonstrations": sum(r["demonstrations"] for r in results), "runs": runs,
        "seeds": [r["seed"] for r in results],
        **_facilitation_figures([r for r in rows if r["kind"] == "wrist"]),
        "hand": _facilitation_figures([r for r in rows if r["kind"] == "hand"]),
        "frames_per_second": frames / seconds if seconds > 0 else float("inf"), "frames": frames, "seconds": seconds,
        "wall_s": wall, "jobs": jobs, "scheduler": scheduler, "rows": rows,
    }


def _facilitation_figures(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Recognition, decision, false-commit, learning and imitation figures of some demonstrations' rows."""
    def stat(values: list[float], f: Any) -> float:
        return float(f(values)) if values else float("nan")

    known_rows = [r for r in rows if not r["novel"]]
    novel_rows = [r for r in rows if r["novel"]]
    fractions = [r["fraction"] for r in known_rows if r["committed"] and r["correct"] and r["fraction"] is not None]
    other_speed = [r for r in known_rows if abs(r["speed"] - 1.0) > 0.15]
    errors = [r["imitation_error"] for r in rows if r["imitation_error"] is not None]
    # the speed factor measured on known movements recognised correctly, against the one they were shown at
    speed_errors = [abs(r["measured_speed"] / r["speed"] - 1.0) for r in known_rows
                    if r["correct"] and r.get("measured_speed") is not None]
    return {
        "known": len(known_rows), "novel": len(novel_rows),
        "recognition_accuracy": sum(r["correct"] for r in known_rows) / max(len(known_rows), 1),
        "accuracy_other_speed": sum(r["correct"] for r in other_speed) / max(len(other_speed), 1),
        "other_speed": len(other_speed),
        "committed_share": sum(r["committed"] for r in known_rows) / max(len(known_rows), 1),
        "decision_fraction_median": float(np.median(fractions)) if fractions else float("nan"),
        "decision_fraction_p90": float(np.percentile(fractions, 90)) if fractions else float("nan"),
        "false_commits": sum(r["false_commit"] for r in rows),
        "edges_per_novel_movement": float(np.mean([r["edges_learned"] for r in novel_rows])) if novel_rows else float("nan"),
        "strokes_per_novel_movement": float(np.mean([r["strokes"] for r in novel_rows])) if novel_rows else float("nan"),
        "imitation_error_mean": stat(errors, np.mean),
        "imitation_error_p90": stat(errors, lambda v: np.percentile(v, 90)),
        "speed_error_median": stat(speed_errors, np.median),
        "speed_error_p90": stat(speed_errors, lambda v: np.percentile(v, 90)),
        "speed_within_10": stat(speed_errors, lambda v: np.mean(np.asarray(v) <= 0.10)),
        "speed_measured": len(speed_errors),
    }


def render_facilitation(r: dict[str, Any]) -> str:
    """The table: one column for the wrist (arm) movements, one for the finger movements of the left hand."""
    columns = [("wrists", r, "m")] + ([("hands", r["hand"], "rad")] if r.get("hand", {}).get("known", 0) + r.get("hand", {}).get("novel", 0) else [])

    def cells(f: dict[str, Any], unit: str) -> list[str]:
        return [
            f"{f['known']} / {f['novel']}",
            f"{f['recognition_accuracy']:.3f}",
            f"{f['accuracy_other_speed']:.3f} ({f['other_speed']})",
            f"{f['committed_share']:.3f}",
            f"{f['decision_fraction_median']:.2f} / {f['decision_fraction_p90']:.2f}",
            f"{f['false_commits']}",
            f"{f['edges_per_novel_movement']:.2f} ({f['strokes_per_novel_movement'] + 1:.2f})",
            f"{f['imitation_error_mean']:.3f} / {f['imitation_error_p90']:.3f} {unit}",
            f"{f['speed_error_median']:.3f} / {f['speed_error_p90']:.3f}",
            f"{f['speed_within_10']:.3f} ({f['speed_measured']})",
        ]

    labels = ["demonstrations (known / novel)", "recognition accuracy, known movements", "  at another speed (how many)",
              "committed before the end (known)", "decision fraction, median / 90th percentile", "false commits",
              "edges learned per novel movement (expected: strokes or 1 hand edge, + the return)",
              "imitation path error, mean / 90th percentile",
              "speed factor error |measured / shown - 1|, median / 90th percentile",
              "speed factor within 10% of the shown (how many measured)"]
    table = [cells(f, unit) for _, f, unit in columns]
    head = (f"likeme bench facilitation: Max watches Moritz (seed {r['seed']}, {r['repertoire']} movements of each kind "
            f"learned first, noise {r['noise']} m and {r.get('angle_noise', 0.0)} rad)")
    rows = [[label, *(col[i] for col in table)] for i, label in enumerate(labels)]
    rows.append(["frames per second (world)", f"{r['frames_per_second']:.0f}", *([""] * (len(columns) - 1))])
    if "wall_s" in r:  # several runs: the wall time of them all, on --jobs processes or the --scheduler's workers
        where = f"--scheduler {r['scheduler']}" if r.get("scheduler") else f"--jobs {r.get('jobs', 1)}"
        rows.append([f"wall time, {r['runs']} runs (seeds {r['seeds'][0]}-{r['seeds'][-1]})", f"{r['wall_s']:.1f} s",
                     *([""] * (len(columns) - 1))])
        rows[-1][0] += f", {where}"
    return "\n".join([head, text_table(rows, [("", "left")] + [(name, "right") for name, _, _ in columns])])


def cmd_facilitation(args: argparse.Namespace, pm: Any) -> int:
    result = facilitation_runs(pm, demonstrations=args.demonstrations, repertoire=args.repertoire, seed=args.seed,
                               noise=args.noise, hands=args.hands, angle_noise=args.angle_noise, progress=not args.quiet,
                               runs=args.runs, jobs=args.jobs, scheduler=args.scheduler)
    print(render_facilitation(result))
    if args.json:
        write_output(args.json, json.dumps(result, indent=2, default=float) + "\n")
    return 0
