"""The ``likeme bench`` command: benchmarks that measure the toolkit's figures.

``likeme bench behaviour`` (§6): random episodes in which Morris is hungry or
playful and food and a toy lie around him (the one he wants in front of him,
the other to his side, or both close together; with or without a screen that
hides his head and nose from Max). Max watches and identifies the first
behaviour; the accuracy of the identified tuple path, motivation (the top-level
tuple) and object is reported per condition against what Morris really did.

``likeme bench watch`` (Buchsbaum & Blumberg 2005, §5): the observer watches the
demonstrator perform a long random sequence of movements through its own
perception (with noise, dropouts and occlusion) and reports

- segmentation precision, recall, F1 and boundary error of its segmenter against
  what the demonstrator really performed (:mod:`plugins.metrics`);
- recognition accuracy of its matcher on the *true* segments;
- the end-to-end movement error rate of what it recognised while watching;
- frames per second of the whole world (acting, perceiving, segmenting, matching).

Results print as a table and can be written as JSON. Speed is measured here, never in tests.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np

from plugins.metrics import match_segments, movement_error_rate, segmentation_scores
from toolkit import ConfigError, World, hookimpl, load_character
from toolkit.character import merge_tables
from toolkit.params import parse_settings


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
    demo = load_character(demonstrator, pm, override={
        "action": {"plugin": "script", "random": movements, "exclude": ["stand", *exclude], "seed": seed, "pause": 0.5}
    })
    obs_override = {"perception": {"plugin": "synthetic-vision", "noise": noise, "dropout": dropout,
                                   "occlusion": occlusion, "seed": seed + 1}}
    obs = load_character(observer, pm, override=merge_tables(obs_override, settings or {}))
    obs.action = None  # watch only: the benchmark measures perception, segmentation and recognition
    world = World(fps=30.0, pm=pm)
    target = world.add_actor(demo, "demonstrator", (0.0, 0.0, 1.6), np.pi)
    watcher = world.add_actor(obs, "observer", (0.0, 0.0, 0.0), 0.0)
    watcher.watch(target)

    limit = int(movements * 4 * world.fps) + 300
    started = time.perf_counter()
    steps = range(limit)
    if progress:
        from rich.progress import track

        steps = track(steps, description=f"{observer} watches {demonstrator}", transient=True)
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
        match = obs.matcher.match(watcher.memory.motion(s, e))
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
        "segmentation": seg,
        "recognition_accuracy": correct / max(len(truth), 1),
        "confusions": dict(sorted(confusions.items(), key=lambda kv: -kv[1])),
        "unsegmented": dict(sorted(missed.items(), key=lambda kv: -kv[1])),
        "movement_error_rate": movement_error_rate(recognised, labels),
        "frames": world.frame,
        "seconds": elapsed,
        "frames_per_second": world.frame / elapsed if elapsed > 0 else float("inf"),
        "real_time_factor": (world.frame / world.fps) / elapsed if elapsed > 0 else float("inf"),
        "python": platform.python_version(),
        "numpy": np.__version__,
    }


BEHAVIOUR_CONDITIONS = ("line-of-sight", "no-line-of-sight", "close-together")


def _episode(pm: Any, rng: np.random.Generator, condition: str) -> dict[str, Any]:
    """One random episode: Morris is hungry or playful, food and a toy lie around him; Max watches and identifies."""
    from toolkit import WorldObject

    drive = str(rng.choice(["hunger", "play"]))
    morris = load_character("morris", pm, override={"action": {"drives": {
        "hunger": {"level": 0.8 if drive == "hunger" else 0.0, "rate": 0.0},
        "play": {"level": 0.8 if drive == "play" else 0.0, "rate": 0.0}}, "seed": int(rng.integers(1 << 30))}})
    max_ = load_character("max", pm, override={"action": {"imitate": False}})
    world = World(fps=30.0, pm=pm)
    target = world.add_actor(morris, "morris", (0.0, 0.0, 1.6), np.pi)
    watcher = world.add_actor(max_, "max", (0.0, 0.0, 0.0), 0.0)
    watcher.watch(target)
    wanted = "cheese" if drive == "hunger" else str(rng.choice(["ball", "baton"]))
    other = str(rng.choice(["ball", "baton"])) if drive == "hunger" else "cheese"

    def place(azimuth_deg: float, distance: float, high: bool) -> np.ndarray:
        a = np.radians(azimuth_deg)  # 0: straight ahead of Morris (towards -z)
        height = rng.uniform(0.75, 1.0) if high else rng.uniform(0.3, 0.5)
        return np.array([distance * np.sin(a), height, 1.6 - distance * np.cos(a)])

    high = bool(rng.random() < 0.3)
    pos_wanted = place(rng.uniform(-12, 12), rng.uniform(0.25, 0.42), high)
    if condition == "close-together":
        pos_other = pos_wanted + np.array([rng.normal(0, 0.02), rng.uniform(-0.02, 0.02), rng.normal(0, 0.02)])
    else:
        side = rng.choice([-1.0, 1.0])
        pos_other = place(side * rng.uniform(45, 80), rng.uniform(0.25, 0.42), bool(rng.random() < 0.3))
    world.add_object(WorldObject(wanted, wanted, pos_wanted, radius=0.035))
    world.add_object(WorldObject(other, other, pos_other, radius=0.035))
    if condition == "no-line-of-sight":
        world.add_object(WorldObject("screen", "screen", (0.0, 0.62, 1.0), radius=0.12))
    world.run(until_idle=True, tail=1.0, max_duration=12.0)
    truth = target.character.action.history
    first = truth[0] if truth else None
    got = None
    if first is not None:  # Max's identification of that same movement (not of a later one)
        movement = target.character.action.hierarchy.tuples[first[1][-1]].movement
        got = next((b for b in world.behaviours("max") if b.movement == movement), None)
    return {
        "condition": condition,
        "drive": drive,
        "object": wanted,
        "true_path": list(first[1]) if first else None,
        "true_object": first[2] if first else None,
        "identified": bool(got is not None and got.known),
        "path": list(got.path) if got is not None and got.known else None,
        "identified_object": got.object if got is not None and got.known else None,
    }


def behaviour_benchmark(pm: Any, *, episodes: int = 100, seed: int = 0, progress: bool = False) -> dict[str, Any]:
    """Identification accuracy (tuple path, motivation, object) per condition over random episodes (B&B §6)."""
    rng = np.random.default_rng(seed)
    jobs = [c for c in BEHAVIOUR_CONDITIONS for _ in range(episodes)]
    started = time.perf_counter()
    if progress:
        from rich.progress import track

        jobs = track(jobs, description="behaviour episodes", transient=True)
    rows = [_episode(pm, rng, c) for c in jobs]
    elapsed = time.perf_counter() - started
    table = {}
    for c in BEHAVIOUR_CONDITIONS:
        sub = [r for r in rows if r["condition"] == c and r["true_path"]]
        n = max(len(sub), 1)
        table[c] = {
            "episodes": len(sub),
            "identified": sum(r["identified"] for r in sub) / n,
            "path": sum(r["path"] == r["true_path"] for r in sub) / n,
            "motivation": sum(bool(r["path"]) and r["path"][0] == r["true_path"][0] for r in sub) / n,
            "object": sum(r["identified_object"] == r["true_object"] for r in sub) / n,
        }
    return {"benchmark": "behaviour", "seed": seed, "episodes_per_condition": episodes, "conditions": table,
            "episodes": rows, "seconds": elapsed, "python": platform.python_version(), "numpy": np.__version__}


def render_behaviour(r: dict[str, Any]) -> str:
    lines = [f"likeme bench behaviour: Max identifies what Morris does (seed {r['seed']}, {r['episodes_per_condition']} "
             f"episodes per condition, {r['seconds']:.0f} s)",
             f"  {'condition':<18} {'episodes':>8} {'identified':>10} {'path':>6} {'motivation':>10} {'object':>6}"]
    for c, t in r["conditions"].items():
        lines.append(f"  {c:<18} {t['episodes']:>8} {t['identified']:>10.3f} {t['path']:>6.3f} {t['motivation']:>10.3f} {t['object']:>6.3f}")
    return "\n".join(lines)


def cmd_behaviour(args: argparse.Namespace, pm: Any) -> int:
    result = behaviour_benchmark(pm, episodes=args.episodes, seed=args.seed, progress=not args.quiet)
    print(render_behaviour(result))
    if args.json:
        _write_json(Path(args.json), result)
    return 0


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
    head = (f"likeme bench watch: {r['observer']} watches {r['demonstrator']} "
            f"(seed {r['seed']}, noise {r['noise']} m, dropout {r['dropout']}, occlusion {'on' if r['occlusion'] else 'off'})")
    comps = ", ".join(f"{k} {v}" for k, v in r["components"].items())
    if r["settings"]:
        comps += "; " + ", ".join(f"{t}.{k} = {v!r}" for t, table in r["settings"].items() for k, v in table.items())
    width = max(len(a) for a, _ in rows)
    lines = [head, f"  {comps}"] + [f"  {a:<{width}}  {b}" for a, b in rows]
    if r["unsegmented"]:
        lines.append("  movements without a matching segment: " + ", ".join(f"{k} ({v})" for k, v in list(r["unsegmented"].items())[:8]))
    if r["confusions"]:
        lines.append("  most frequent confusions: " + ", ".join(f"{k} ({v})" for k, v in list(r["confusions"].items())[:6]))
    return "\n".join(lines)


def cmd_watch(args: argparse.Namespace, pm: Any) -> int:
    result = watch_benchmark(
        pm, observer=args.observer, demonstrator=args.demonstrator, movements=args.movements, seed=args.seed,
        noise=args.noise, dropout=args.dropout, occlusion=not args.no_occlusion, progress=not args.quiet,
        settings=parse_settings(args.set),
    )
    print(render_watch(result))
    if args.json:
        _write_json(Path(args.json), result)
    return 0


def _write_json(path: Path, data: dict[str, Any]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, default=float) + "\n", encoding="utf-8")
    tmp.replace(path)


@hookimpl
def likeme_register_commands(subparsers):
    bench = subparsers.add_parser("bench", help="measure accuracy and speed (benchmarks)")
    sub = bench.add_subparsers(dest="benchmark", metavar="BENCHMARK", parser_class=type(bench), required=True)
    from plugins.mocap_benchmark import add_commands

    add_commands(sub)  # recognition, segmentation, stream on motion-capture files, and the data they read
    p = sub.add_parser("watch", help="an observer watches a demonstrator's random movements (B&B §5)")
    p.add_argument("--observer", default="max", help="observer character (default: max)")
    p.add_argument("--demonstrator", default="morris", help="demonstrator character (default: morris)")
    p.add_argument("--movements", type=int, default=200, help="number of random movements (default: 200)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--noise", type=float, default=0.005, help="vision noise, metres (default: 0.005)")
    p.add_argument("--dropout", type=float, default=0.05, help="per-part dropout probability (default: 0.05)")
    p.add_argument("--no-occlusion", action="store_true", help="switch occlusion off")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE",
                   help="override an observer parameter, e.g. --set segmenter.floor=0 (repeatable)")
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=cmd_watch)

    p = sub.add_parser("facilitation", help="Max learns Moritz's arm and finger movements and imitates familiar ones early (K&G §4-5)")
    p.add_argument("--demonstrations", type=int, default=200, help="demonstrations after the repertoire (default: 200)")
    p.add_argument("--repertoire", type=int, default=6, help="random movements learned first (default: 6)")
    p.add_argument("--noise", type=float, default=0.002, help="observation noise, metres (default: 0.002)")
    p.add_argument("--hands", type=float, default=0.3, help="share of finger movements of the left hand among the "
                   "demonstrations (default: 0.3; 0: arms only)")
    p.add_argument("--angle-noise", type=float, default=0.005, help="observation noise on finger joint angles, radians "
                   "(default: 0.005)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=cmd_facilitation)

    p = sub.add_parser("behaviour", help="an observer identifies the behaviour, motivation and object of a demonstrator (B&B §6)")
    p.add_argument("--episodes", type=int, default=100, help="random episodes per condition (default: 100)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", metavar="FILE", help="also write the results (every episode) as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=cmd_behaviour)

    p = sub.add_parser("vision", help="rendered-vision against synthetic-vision on the same frames: agreement, "
                       "position difference, milliseconds per frame")
    p.add_argument("--scenario", default="jump_then_cover_face", help="scenario to watch (default: jump_then_cover_face)")
    p.add_argument("--observer", default="max", help="the watching actor (default: max)")
    p.add_argument("--resolution", type=int, action="append", help="rendered-vision resolution, repeatable "
                   "(default: 240, 480, 960)")
    p.add_argument("--frames", type=int, default=240, help="frames to compare (default: 240)")
    p.set_defaults(handler=cmd_vision)


def vision_benchmark(pm: Any, scenario: str, observer: str, resolutions: list[int], frames: int) -> list[dict[str, Any]]:
    """Step the scenario; on every frame both perceptions look at the watched actor; compare and time them."""
    from plugins.rendered_vision import RenderedVision
    from plugins.synthetic_vision import SyntheticVision
    from toolkit.scenario import load_scenario

    world = load_scenario(scenario, pm).world
    actor = world.actors[observer]
    target = actor.target
    if target is None:
        raise ConfigError(f"actor {observer!r} watches nobody in {scenario!r}", key=("--observer",),
                          expected="an actor that watches another", available=[a.id for a in world.actors.values()
                                                                               if a.target is not None])
    params = dict(actor.character.perception.params) if actor.character.perception is not None else {}
    params = {k: v for k, v in params.items() if k in {q.name for q in SyntheticVision.parameters}}
    geometric = SyntheticVision(**params)
    geometric.attach(actor.character)
    rendered = {r: RenderedVision(**params, resolution=r) for r in resolutions}
    for v in rendered.values():
        v.attach(actor.character)
    geometric_time = 0.0
    stats = {r: {"time": 0.0, "agree": 0, "n": 0, "errors": []} for r in resolutions}
    try:
        for _ in range(frames):
            world.step()
            t0 = time.perf_counter()
            truth_p, truth_s, _ = geometric._look(actor, target, world)
            geometric_time += time.perf_counter() - t0
            for r, v in rendered.items():
                row = stats[r]
                t0 = time.perf_counter()
                p, s, _ = v._look(actor, target, world)
                row["time"] += time.perf_counter() - t0
                row["agree"] += int((s == truth_s).sum())
                row["n"] += len(s)
                both = s & truth_s
                row["errors"] += list(np.linalg.norm(p[both] - truth_p[both], axis=1))
    finally:
        for v in rendered.values():
            v.close()
    out = [{"perception": "synthetic-vision", "ms_per_frame": 1000 * geometric_time / frames, "agreement": 1.0,
            "median_mm": 0.0, "p95_mm": 0.0}]
    for r, row in stats.items():
        errors = np.array(row["errors"] or [np.nan])
        out.append({"perception": f"rendered-vision {r} px", "ms_per_frame": 1000 * row["time"] / frames,
                    "agreement": row["agree"] / row["n"], "median_mm": 1000 * float(np.median(errors)),
                    "p95_mm": 1000 * float(np.percentile(errors, 95))})
    return out


def cmd_vision(args: argparse.Namespace, pm: Any) -> int:
    rows = vision_benchmark(pm, args.scenario, args.observer, args.resolution or [240, 480, 960], args.frames)
    print(f"{args.observer} watching in {args.scenario}, {args.frames} frames")
    print(f"{'perception':<26} {'ms/frame':>9} {'seen-agreement':>15} {'median mm':>10} {'p95 mm':>8}")
    for r in rows:
        print(f"{r['perception']:<26} {r['ms_per_frame']:9.2f} {r['agreement']:15.3f} {r['median_mm']:10.1f} "
              f"{r['p95_mm']:8.1f}")
    return 0


# -- Max and Moritz (Kopp & Graeser 2006) -----------------------------------------------------------------


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
    from plugins.guiding_stroke import SHAPES, GuidingStroke
    from plugins.motor_command_graph import place_elbows
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
    from plugins.hand_transition import HandTransition
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
        from rich.progress import track

        jobs = track(jobs, description="demonstrations", transient=True)
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
            executed = np.concatenate([st.trajectory(fps) for e in final.path for st in learner.motor.edge(e)[3]["commands"]])
            shown = np.concatenate([st.trajectory(fps) for st in strokes])
            imitation_error = _shape_error(executed, shown)
        elif final is not None and final.path and learner.motor.edge(final.path[0])[0] == "left_hand":
            # per finger, the path of its joint angles (radians) along the commands performed against the one shown
            executed = [np.concatenate([learner.motor.edge(e)[3]["commands"][j].trajectory(fps) for e in final.path])
                        for j in range(len(strokes))]
            grid = np.linspace(0.0, strokes[0].duration, 100)
            imitation_error = float(np.mean([_shape_error(x, t.curve(grid)) for x, t in zip(executed, strokes)]))
        rows.append({
            "kind": kind,
            "novel": is_novel,
            "speed": speed,
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
        "rows": rows, "python": platform.python_version(), "numpy": np.__version__,
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
        ]

    labels = ["demonstrations (known / novel)", "recognition accuracy, known movements", "  at another speed (how many)",
              "committed before the end (known)", "decision fraction, median / 90th percentile", "false commits",
              "edges learned per novel movement (expected: strokes or 1 hand edge, + the return)",
              "imitation path error, mean / 90th percentile"]
    table = [cells(f, unit) for _, f, unit in columns]
    width = max(len(a) for a in labels)
    widths = [max(len(name), *(len(c) for c in col)) for (name, _, _), col in zip(columns, table)]
    head = (f"likeme bench facilitation: Max watches Moritz (seed {r['seed']}, {r['repertoire']} movements of each kind "
            f"learned first, noise {r['noise']} m and {r.get('angle_noise', 0.0)} rad)")
    lines = [head, f"  {'':<{width}}  " + "  ".join(f"{name:>{w}}" for (name, _, _), w in zip(columns, widths))]
    for i, label in enumerate(labels):
        lines.append(f"  {label:<{width}}  " + "  ".join(f"{col[i]:>{w}}" for col, w in zip(table, widths)))
    lines.append(f"  {'frames per second (world)':<{width}}  {r['frames_per_second']:.0f}")
    return "\n".join(lines)


def cmd_facilitation(args: argparse.Namespace, pm: Any) -> int:
    result = facilitation_benchmark(pm, demonstrations=args.demonstrations, repertoire=args.repertoire, seed=args.seed,
                                    noise=args.noise, hands=args.hands, angle_noise=args.angle_noise, progress=not args.quiet)
    print(render_facilitation(result))
    if args.json:
        _write_json(Path(args.json), result)
    return 0
