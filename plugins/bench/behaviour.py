"""``likeme bench behaviour``: an observer identifies what a demonstrator does and why (Buchsbaum & Blumberg 2005, §6).

Random episodes in which Morris is hungry or playful and food and a toy lie around him (the one he wants in front
of him, the other to his side, or both close together; with or without a screen that hides his head and nose from
Max; or both anywhere within his reach, ``random-placement``, where only his turning head shows which one he
wants). Max watches and identifies the first behaviour; the accuracy of the identified tuple path, motivation (the
top-level tuple) and object is reported per condition against what Morris really did.

The episodes are drawn first, as plain data, and then run in this process or, with ``--jobs N`` or ``--scheduler
ADDRESS``, in other processes (:func:`plugins.bench.jobs.run_items`); the figures are the same wherever they ran.
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
from toolkit import World, load_character
from toolkit.files import write_output

__all__ = ["BEHAVIOUR_CONDITIONS", "behaviour_benchmark", "render_behaviour", "cmd_behaviour", "world_name"]


BEHAVIOUR_CONDITIONS = ("line-of-sight", "no-line-of-sight", "close-together", "random-placement")
"""The conditions, in the order their episodes are drawn (a condition added at the end leaves the others' episodes
as they were)."""

MORRIS_AT = (0.0, 0.0, 1.6)
"""Where Morris stands (facing Max, who stands at the origin facing +z)."""
REACH = (0.25, 0.42)
"""Horizontal distances (m) from Morris's root at which objects are placed: within his reach (0.5 m)."""
SIDE = 90.0
"""``random-placement``: objects lie anywhere within reach on the side of Morris where his hands go, at azimuths
(degrees from straight ahead) drawn uniformly in [-SIDE, SIDE]."""
COLOURS = {"cheese": "#ffd700", "ball": "#ff4040", "baton": "#8040ff", "screen": "#808080"}
"""What each object of an episode looks like (Max knows them by these looks, characters/max.toml)."""


def _draw(rng: np.random.Generator, condition: str) -> dict[str, Any]:
    """One random episode as plain data (drive, Morris's seed, where the objects lie), drawn from ``rng``.

    Every random draw of an episode happens here, in the parent process and in the episodes' order, so an episode
    does not depend on which process runs it (:func:`plugins.bench.jobs.run_items`).
    """
    drive = str(rng.choice(["hunger", "play"]))
    seed = int(rng.integers(1 << 30))
    wanted = "cheese" if drive == "hunger" else str(rng.choice(["ball", "baton"]))
    other = str(rng.choice(["ball", "baton"])) if drive == "hunger" else "cheese"

    def place(azimuth_deg: float, distance: float, high: bool) -> list[float]:
        a = np.radians(azimuth_deg)  # 0: straight ahead of Morris (towards -z)
        height = rng.uniform(0.75, 1.0) if high else rng.uniform(0.3, 0.5)
        return [float(distance * np.sin(a)), float(height), float(MORRIS_AT[2] - distance * np.cos(a))]

    if condition == "random-placement":  # both anywhere within reach: nothing puts the wanted one in front
        pos_wanted = place(rng.uniform(-SIDE, SIDE), rng.uniform(*REACH), bool(rng.random() < 0.3))
        pos_other = place(rng.uniform(-SIDE, SIDE), rng.uniform(*REACH), bool(rng.random() < 0.3))
    else:
        high = bool(rng.random() < 0.3)
        pos_wanted = place(rng.uniform(-12, 12), rng.uniform(*REACH), high)
        if condition == "close-together":
            pos_other = [float(x) for x in np.asarray(pos_wanted) + np.array(
                [rng.normal(0, 0.02), rng.uniform(-0.02, 0.02), rng.normal(0, 0.02)])]
        else:
            side = rng.choice([-1.0, 1.0])
            pos_other = place(side * rng.uniform(45, 80), rng.uniform(*REACH), bool(rng.random() < 0.3))
    return {"condition": condition, "drive": drive, "seed": seed, "wanted": wanted, "other": other,
            "positions": {wanted: pos_wanted, other: pos_other}}


def world_name(world: Any, observer: str, name: str | None) -> str | None:
    """The world's name of the object ``observer`` calls ``name``: the world object nearest to where the observer
    first saw it, as the world was then (ground truth, for judging an observer; the observer never reads it)."""
    actor = world.actors[observer]
    sightings = actor.sightings
    if name is None or sightings is None:
        return None
    rows, positions = sightings.track(name, sightings.n - 1)
    if not len(rows):
        return None
    then = world.objects_at(actor.watch_start + int(rows[0]))
    if not then:
        return None
    return min(then, key=lambda n: float(np.linalg.norm(then[n].position - positions[0])))


_WORKER_PM: Any = None


def _run_episode(item: dict[str, Any], pm: Any = None) -> dict[str, Any]:
    """Run one drawn episode (:func:`_draw`): Morris acts, Max watches and identifies; in any process.

    Without ``pm`` (a worker of ``--jobs`` or ``--scheduler``) the process's own plugin manager is made once.
    """
    from toolkit import WorldObject

    global _WORKER_PM
    if pm is None:
        if _WORKER_PM is None:
            from toolkit.manager import create_plugin_manager

            _WORKER_PM = create_plugin_manager()
        pm = _WORKER_PM
    drive, condition, wanted = item["drive"], item["condition"], item["wanted"]
    morris = load_character("morris", pm, override={"action": {"drives": {
        "hunger": {"level": 0.8 if drive == "hunger" else 0.0, "rate": 0.0},
        "play": {"level": 0.8 if drive == "play" else 0.0, "rate": 0.0}}, "seed": item["seed"]}})
    max_ = load_character("max", pm, override={"action": {"imitate": False}})
    if item.get("perception", "own") == "synthetic-vision":  # the same eye, radii and looks, found by geometry
        from plugins.bench.vision import geometric_params

        max_ = load_character("max", pm, override={"action": {"imitate": False}, "perception": {
            "plugin": "synthetic-vision", **geometric_params(max_.perception)}})
    world = World(fps=30.0, pm=pm)
    target = world.add_actor(morris, "morris", MORRIS_AT, np.pi)
    watcher = world.add_actor(max_, "max", (0.0, 0.0, 0.0), 0.0)
    watcher.watch(target)
    for name, position in item["positions"].items():
        world.add_object(WorldObject(name, name, position, radius=0.035, colour=COLOURS[name]))
    if condition == "no-line-of-sight":
        world.add_object(WorldObject("screen", "screen", (0.0, 0.62, 1.0), radius=0.12, colour=COLOURS["screen"]))
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
        "positions": item["positions"],
        "true_path": list(first[1]) if first else None,
        "true_object": first[2] if first else None,
        "identified": bool(got is not None and got.known),
        "path": list(got.path) if got is not None and got.known else None,
        "identified_object": world_name(world, "max", got.object) if got is not None and got.known else None,
        "line_of_sight": world_name(world, "max", got.details.get("line_of_sight")) if got is not None else None,
        "in_sight": sorted(world_name(world, "max", n) for n in got.details.get("in_sight", {})) if got is not None else [],
    }


def behaviour_benchmark(pm: Any, *, episodes: int = 100, seed: int = 0, progress: bool = False, jobs: int = 1,
                        scheduler: str | None = None, conditions: tuple[str, ...] = BEHAVIOUR_CONDITIONS,
                        perception: str = "own") -> dict[str, Any]:
    """Identification accuracy (tuple path, motivation, object) per condition over random episodes (B&B §6).

    The episodes are drawn here from ``seed`` (every condition's in :data:`BEHAVIOUR_CONDITIONS` order, whichever
    are run), then run in this process (``jobs`` 1, with ``pm``), in ``jobs`` local processes or on a Dask cluster
    (``scheduler``): the figures do not depend on where they ran. ``perception``: ``"own"``, Max's as
    ``characters/max.toml`` gives it (rendered vision), or ``"synthetic-vision"``, the geometric eye in its place.
    """
    from plugins.bench.jobs import run_items

    rng = np.random.default_rng(seed)
    drawn = [_draw(rng, c) for c in BEHAVIOUR_CONDITIONS for _ in range(episodes)]
    items = [{**d, "perception": perception} for d in drawn if d["condition"] in conditions]
    started = time.perf_counter()
    if jobs == 1 and not scheduler:
        rows = [_run_episode(item, pm) for item in (progress_bar(items, "behaviour episodes") if progress else items)]
    else:
        rows = run_items(_run_episode, items, jobs=jobs, scheduler=scheduler)
    elapsed = time.perf_counter() - started
    table = {}
    for c in conditions:
        sub = [r for r in rows if r["condition"] == c and r["true_path"]]
        n = max(len(sub), 1)
        table[c] = {
            "episodes": len(sub),
            "identified": sum(r["identified"] for r in sub) / n,
            "path": sum(r["path"] == r["true_path"] for r in sub) / n,
            "motivation": sum(bool(r["path"]) and r["path"][0] == r["true_path"][0] for r in sub) / n,
            "object": sum(r["identified_object"] == r["true_object"] for r in sub) / n,
        }
    return {"benchmark": "behaviour", "seed": seed, "episodes_per_condition": episodes, "perception": perception,
            "conditions": table,
            "episodes": rows, "seconds": elapsed, "jobs": jobs, "python": platform.python_version(),
            "numpy": np.__version__}


def render_behaviour(r: dict[str, Any]) -> str:
    from plugins.bench import text_table

    head = (f"likeme bench behaviour: Max identifies what Morris does (seed {r['seed']}, {r['episodes_per_condition']} "
            f"episodes per condition, perception: {r.get('perception', 'own')}, {r['seconds']:.0f} s)")
    rows = [[c, t["episodes"], f"{t['identified']:.3f}", f"{t['path']:.3f}", f"{t['motivation']:.3f}",
             f"{t['object']:.3f}"] for c, t in r["conditions"].items()]
    columns = [("condition", "left")] + [(name, "right") for name in ("episodes", "identified", "path", "motivation",
                                                                        "object")]
    return "\n".join([head, text_table(rows, columns)])


def cmd_behaviour(args: argparse.Namespace, pm: Any) -> int:
    result = behaviour_benchmark(pm, episodes=args.episodes, seed=args.seed, progress=not args.quiet,
                                 jobs=args.jobs, scheduler=args.scheduler, perception=args.perception)
    print(render_behaviour(result))
    if args.json:
        write_output(args.json, json.dumps(result, indent=2, default=float) + "\n")
    return 0
