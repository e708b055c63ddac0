"""``likeme bench vision``: rendered vision against synthetic vision (Buchsbaum & Blumberg 2005, §4.2).

Two measurements, both side by side in one run:

- *per frame* (the default): both perceptions look at the watched actor on every frame of a scenario; the share of
  part-frames both see or both miss, the position difference over parts both see (median, 95th percentile and root
  mean square), the root mean square the rendered eye's own model of its error predicts there
  (:meth:`~plugins.perception.rendered_vision.RenderedVision.position_uncertainty`, what an observer reading a gaze
  allows for), and milliseconds per frame. Each resolution is an item of ``--jobs`` / ``--scheduler`` that steps the
  scenario itself (the scenario's world is deterministic), so the agreement and the differences do not depend on the
  workers; the milliseconds are measured inside each worker;
- *per scenario* (``--scenarios``): every scenario in which a character watches, run to its end with the watcher's
  perception as its file gives it and with synthetic vision in its place (the same eye, part radii and looks), each
  ``--repeats`` times, alternating; the median seconds of each, their ratio, and whether the watcher concluded the
  same (the same movements recognised and behaviours identified, about the same objects of the world).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

from plugins.bench import text_table
from toolkit import ConfigError

__all__ = ["vision_benchmark", "scenario_benchmark", "cmd_vision"]


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
             "median_mm": 0.0, "p95_mm": 0.0, "rms_mm": 0.0, "model_mm": 0.0}] + [r["row"] for r in results]


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


def geometric_params(perception: Any) -> dict[str, Any]:
    """A perception's parameters that synthetic vision has too (its eye, field of view, part radii, looks, noise):
    synthetic vision in its place sees with the same eye."""
    from plugins.perception.synthetic_vision import SyntheticVision

    params = dict(perception.params) if perception is not None else {}
    return {k: v for k, v in params.items() if k in {q.name for q in SyntheticVision.parameters}}


def _compare(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """Step the scenario; on every frame synthetic vision and rendered vision at the item's resolution look at the
    watched actor; compare and time them."""
    from plugins.perception.rendered_vision import RenderedVision
    from plugins.perception.synthetic_vision import SyntheticVision
    from toolkit.watching import guarded

    world, actor, target = _watched(pm, item["scenario"], item["observer"])
    frames, resolution = item["frames"], item["resolution"]
    own = actor.character.perception.params if actor.character.perception is not None else {}
    rendered_only = {q.name for q in RenderedVision.parameters} - {q.name for q in SyntheticVision.parameters}
    params = geometric_params(actor.character.perception)
    geometric = SyntheticVision(**params)
    geometric.attach(actor.character)
    rendered = RenderedVision(**params, **{k: v for k, v in own.items() if k in rendered_only and k != "resolution"},
                              resolution=resolution)
    rendered.attach(actor.character)
    geometric_time = rendered_time = 0.0
    agree = n = 0
    errors: list[float] = []
    modelled: list[float] = []
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
            across, along = rendered.position_uncertainty(np.linalg.norm(truth_p[both] - rendered.eye(actor), axis=1))
            modelled += list(2 * across**2 + along**2)
    finally:
        rendered.close()
    spread = np.array(errors or [np.nan])
    return {"synthetic_ms": 1000 * geometric_time / frames,
            "row": {"perception": f"rendered-vision {resolution} px", "ms_per_frame": 1000 * rendered_time / frames,
                    "agreement": agree / n, "median_mm": 1000 * float(np.median(spread)),
                    "p95_mm": 1000 * float(np.percentile(spread, 95)),
                    "rms_mm": 1000 * float(np.sqrt(np.mean(spread**2))),
                    "model_mm": 1000 * float(np.sqrt(np.mean(modelled))) if modelled else float("nan")}}


def _watchers(world: Any) -> list[Any]:
    return [a for a in world.actors.values() if a.target is not None and a.character.perception is not None]


def _conclusions(world: Any) -> list[tuple]:
    """What every watcher concluded: the movements recognised and the behaviours identified, in order; an object by
    the world's name of what the watcher saw (each perception names what it sees itself)."""
    from plugins.bench.behaviour import world_name

    out = []
    for actor in _watchers(world):
        out += [(actor.id, "match", e.data["match"].movement) for e in world.events_of("movement_recognised", actor.id)]
        out += [(actor.id, "behaviour", b.known, b.movement, b.path, world_name(world, actor.id, b.object))
                for b in world.behaviours(actor.id)]
    return out


def _run_scenario(pm: Any, name: str, geometric: bool) -> tuple[float, list[tuple], str]:
    """Run scenario ``name`` once (its watchers' perception, or synthetic vision in its place): seconds,
    conclusions, and the perception the watchers saw with."""
    from plugins.perception.synthetic_vision import SyntheticVision
    from toolkit.scenario import load_scenario

    scenario = load_scenario(name, pm)
    used = set()
    for actor in _watchers(scenario.world):
        if geometric and actor.character.perception.name != "synthetic-vision":
            vision = SyntheticVision(**geometric_params(actor.character.perception))
            vision.attach(actor.character)
            vision.reset(scenario.world.fps)
            actor.character.perception = vision
        used.add(actor.character.perception.name)
    t0 = time.perf_counter()
    world = scenario.run()
    seconds = time.perf_counter() - t0
    for actor in _watchers(world):
        close = getattr(actor.character.perception, "close", None)
        if close is not None:
            close()
    return seconds, _conclusions(world), ", ".join(sorted(used))


def scenario_benchmark(pm: Any, names: list[str], repeats: int = 3) -> list[dict[str, Any]]:
    """Each scenario run ``repeats`` times with its watchers' own perception and with synthetic vision, alternating:
    median seconds, the ratio, whether they concluded the same, and with which perception (see the module)."""
    rows = []
    for name in names:
        own, geo = [], []
        for _ in range(repeats):
            seconds, mine, used = _run_scenario(pm, name, geometric=False)
            own.append(seconds)
            seconds, theirs, _ = _run_scenario(pm, name, geometric=True)
            geo.append(seconds)
        rows.append({"scenario": name, "perception": used, "seconds": float(np.median(own)),
                     "synthetic_seconds": float(np.median(geo)), "same": mine == theirs})
    return rows


def _scenario_names(pm: Any) -> list[str]:
    """The built-in scenarios in which a character watches another."""
    from toolkit.character import builtin_characters
    from toolkit.scenario import load_scenario

    return [path.stem for path in sorted((builtin_characters() / "scenarios").glob("*.toml"))
            if _watchers(load_scenario(path, pm).world)]


def cmd_vision(args: argparse.Namespace, pm: Any) -> int:
    if args.scenarios:
        rows = scenario_benchmark(pm, args.scenario_name or _scenario_names(pm), args.repeats)
        print(f"every scenario with a watcher, its perception against synthetic vision (median of {args.repeats} "
              "runs each, alternating)")
        columns = [("scenario", "left"), ("perception", "left"), ("seconds", "right"), ("synthetic s", "right"),
                   ("ratio", "right"), ("same conclusions", "left")]
        print(text_table([[r["scenario"], r["perception"], f"{r['seconds']:.2f}", f"{r['synthetic_seconds']:.2f}",
                           f"{r['seconds'] / r['synthetic_seconds']:.1f}", "yes" if r["same"] else "no"] for r in rows],
                         columns, indent=0))
        return 0
    rows = vision_benchmark(pm, args.scenario, args.observer, args.resolution or [240, 480, 960], args.frames,
                            jobs=args.jobs, scheduler=args.scheduler)
    print(f"{args.observer} watching in {args.scenario}, {args.frames} frames")
    columns = [("perception", "left")] + [(name, "right") for name in ("ms/frame", "seen-agreement", "median mm",
                                                                         "p95 mm", "rms mm", "model rms mm")]
    print(text_table([[r["perception"], f"{r['ms_per_frame']:.2f}", f"{r['agreement']:.3f}", f"{r['median_mm']:.1f}",
                       f"{r['p95_mm']:.1f}", f"{r['rms_mm']:.1f}", f"{r['model_mm']:.1f}"] for r in rows],
                     columns, indent=0))
    return 0
