"""``likeme bench vision``: rendered vision against synthetic vision on the same frames (Buchsbaum & Blumberg 2005, §4.2).

Both perceptions look at the watched actor on every frame of a scenario: the share of part-frames both see or both
miss, the position difference over parts both see, and milliseconds per frame. Each resolution is an item of
``--jobs`` / ``--scheduler`` that steps the scenario itself (the scenario's world is deterministic), so the agreement
and the differences do not depend on the workers; the milliseconds are measured inside each worker.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

from plugins.bench import text_table
from toolkit import ConfigError

__all__ = ["vision_benchmark", "cmd_vision"]


def vision_benchmark(pm: Any, scenario: str, observer: str, resolutions: list[int], frames: int, *, jobs: int = 1,
                     scheduler: str | None = None) -> list[dict[str, Any]]:
    """One row per perception: synthetic vision, then rendered vision at each of ``resolutions``.

    Each resolution is an item (:func:`plugins.bench.jobs.run_with_pm`: ``jobs`` local processes or the Dask
    ``scheduler``) that steps the scenario itself and times both perceptions on every frame; the synthetic row's
    milliseconds are the first item's."""
    from plugins.bench.jobs import run_with_pm

    _watched(pm, scenario, observer)  # a bad --scenario or --observer fails here, before any worker starts
    items = [{"scenario": scenario, "observer": observer, "resolution": r, "frames": frames} for r in resolutions]
    results = run_with_pm(_compare, items, pm, jobs=jobs, scheduler=scheduler)
    return [{"perception": "synthetic-vision", "ms_per_frame": results[0]["synthetic_ms"], "agreement": 1.0,
             "median_mm": 0.0, "p95_mm": 0.0}] + [r["row"] for r in results]


def _watched(pm: Any, scenario: str, observer: str) -> tuple[Any, Any, Any]:
    """The scenario's world, the watching actor and the actor it watches."""
    from toolkit.scenario import load_scenario

    world = load_scenario(scenario, pm).world
    if observer not in world.actors:
        raise ConfigError(f"no actor {observer!r} in {scenario!r}", key=("--observer",),
                          expected="an actor of the scenario that watches another",
                          available=[a.id for a in world.actors.values() if a.target is not None])
    actor = world.actors[observer]
    if actor.target is None:
        raise ConfigError(f"actor {observer!r} watches nobody in {scenario!r}", key=("--observer",),
                          expected="an actor that watches another", available=[a.id for a in world.actors.values()
                                                                               if a.target is not None])
    return world, actor, actor.target


def _compare(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """Step the scenario; on every frame synthetic vision and rendered vision at the item's resolution look at the
    watched actor; compare and time them."""
    from plugins.perception.rendered_vision import RenderedVision
    from plugins.perception.synthetic_vision import SyntheticVision
    from toolkit.watching import guarded

    world, actor, target = _watched(pm, item["scenario"], item["observer"])
    frames, resolution = item["frames"], item["resolution"]
    params = dict(actor.character.perception.params) if actor.character.perception is not None else {}
    params = {k: v for k, v in params.items() if k in {q.name for q in SyntheticVision.parameters}}
    geometric = SyntheticVision(**params)
    geometric.attach(actor.character)
    rendered = RenderedVision(**params, resolution=resolution)
    rendered.attach(actor.character)
    geometric_time = rendered_time = 0.0
    agree = n = 0
    errors: list[float] = []
    try:
        for _ in range(frames):
            world.step()
            t0 = time.perf_counter()
            truth_p, truth_s, _ = guarded(geometric, "look", actor, target, world)
            geometric_time += time.perf_counter() - t0
            t0 = time.perf_counter()
            p, s, _ = guarded(rendered, "look", actor, target, world)
            rendered_time += time.perf_counter() - t0
            agree += int((s == truth_s).sum())
            n += len(s)
            both = s & truth_s
            errors += list(np.linalg.norm(p[both] - truth_p[both], axis=1))
    finally:
        rendered.close()
    spread = np.array(errors or [np.nan])
    return {"synthetic_ms": 1000 * geometric_time / frames,
            "row": {"perception": f"rendered-vision {resolution} px", "ms_per_frame": 1000 * rendered_time / frames,
                    "agreement": agree / n, "median_mm": 1000 * float(np.median(spread)),
                    "p95_mm": 1000 * float(np.percentile(spread, 95))}}


def cmd_vision(args: argparse.Namespace, pm: Any) -> int:
    rows = vision_benchmark(pm, args.scenario, args.observer, args.resolution or [240, 480, 960], args.frames,
                            jobs=args.jobs, scheduler=args.scheduler)
    print(f"{args.observer} watching in {args.scenario}, {args.frames} frames")
    columns = [("perception", "left")] + [(name, "right") for name in ("ms/frame", "seen-agreement", "median mm",
                                                                         "p95 mm")]
    print(text_table([[r["perception"], f"{r['ms_per_frame']:.2f}", f"{r['agreement']:.3f}", f"{r['median_mm']:.1f}",
                       f"{r['p95_mm']:.1f}"] for r in rows], columns, indent=0))
    return 0
