"""``likeme bench vision``: rendered vision against synthetic vision on the same frames (Buchsbaum & Blumberg 2005, §4.2).

Both perceptions look at the watched actor on every frame of a scenario: the share of part-frames both see or both
miss, the position difference over parts both see, and milliseconds per frame.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

from plugins.bench import text_table
from toolkit import ConfigError

__all__ = ["vision_benchmark", "cmd_vision"]


def vision_benchmark(pm: Any, scenario: str, observer: str, resolutions: list[int], frames: int) -> list[dict[str, Any]]:
    """Step the scenario; on every frame both perceptions look at the watched actor; compare and time them."""
    from plugins.perception.rendered_vision import RenderedVision
    from plugins.perception.synthetic_vision import SyntheticVision
    from toolkit.scenario import load_scenario
    from toolkit.watching import guarded

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
            truth_p, truth_s, _ = guarded(geometric, "look", actor, target, world)
            geometric_time += time.perf_counter() - t0
            for r, v in rendered.items():
                row = stats[r]
                t0 = time.perf_counter()
                p, s, _ = guarded(v, "look", actor, target, world)
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
    columns = [("perception", "left")] + [(name, "right") for name in ("ms/frame", "seen-agreement", "median mm",
                                                                         "p95 mm")]
    print(text_table([[r["perception"], f"{r['ms_per_frame']:.2f}", f"{r['agreement']:.3f}", f"{r['median_mm']:.1f}",
                       f"{r['p95_mm']:.1f}"] for r in rows], columns, indent=0))
    return 0
