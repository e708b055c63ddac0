"""``likeme bench learning``: a new movement learned from one demonstration against one learned from several (§7.3).

Buchsbaum & Blumberg 2005, §7.3: "The problem of distinguishing genuinely novel movements could be lessened through
repeated demonstration and observation. This would allow the observing character to develop a model of the new
movement, allowing for more reliable comparisons to existing movement representations." On generated data:

- the *new movements*: Morris's windmill, which Max has not got, and ``--generated`` more, each made of two random
  arm poses of Morris's (both hands and elbows moved from his stand by up to 20 cm) swung between, stand to stand;
- a *take* of one is Morris performing it as people repeat a movement, never twice alike: at a speed drawn in
  [0.8, 1.25], its swing from the stand scaled by a factor in [0.85, 1.15], each part held ``--jitter`` metres off
  (one offset per part and take), and every position seen with ``--noise`` metres of Gaussian noise per frame;
- for each new movement and trial, Max (his posegraph and path search, as in ``characters/max.toml``, keeping up to
  the largest k takes) learns it from the first k takes (:meth:`plugins.motor.posegraph.Posegraph.learn_takes`: one take is the paper's learning;
  several make the mean path and stay takes of it), then watches ``--tests`` fresh takes; a take is *recognised*
  when path search answers the learned movement, *unknown* when it answers nothing, *other* when another movement.
  ``false`` is the share of Morris's versions of Max's own movements (the same variation) that path search takes
  for the learned one: learning from more takes must not make it swallow what Max already knew.

Each (movement, trial) is an item of ``--jobs`` / ``--scheduler``; its takes are drawn from its own seed, so the
figures do not depend on where it ran.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from plugins.bench import text_table
from toolkit import Motion, load_character
from toolkit.files import write_output

__all__ = ["learning_benchmark", "render_learning", "cmd_learning", "take"]

NAME = "new"
"""What the learned movement is called in each trial."""


def _novel(rng: np.random.Generator, morris: Any) -> tuple[np.ndarray, np.ndarray]:
    """A generated new movement: key poses (5, P, 3) stand, A, B, A, stand at times (5,) seconds."""
    body = morris.body
    stand = morris.motor.rest_pose()
    moved = [body.index(p) for p in ("left_hand", "right_hand", "left_elbow", "right_elbow")]

    def pose() -> np.ndarray:
        out = stand.copy()
        reach = rng.uniform(-0.2, 0.2, (2, 3))
        out[moved[:2]] += reach
        out[moved[2:]] += reach / 2
        return out

    a, b = pose(), pose()
    return np.stack([stand, a, b, a, stand]), np.array([0.0, 0.5, 1.0, 1.5, 2.0])


def take(keys: np.ndarray, times: np.ndarray, morris: Any, rng: np.random.Generator, *, noise: float,
         jitter: float, fps: float = 30.0) -> Motion:
    """One take of a movement given by key poses (K, P, 3) at ``times``: a speed, a swing and a posture of its own,
    seen with noise (see the module); root-relative, as an observer perceives it."""
    from plugins.motor.key_poses import interpolate

    stand = keys[0]
    swing = rng.uniform(0.85, 1.15)
    offset = rng.normal(0.0, jitter, stand.shape)
    shaped = stand + swing * (keys - stand) + offset[None]
    shaped[0], shaped[-1] = stand, stand  # it starts and ends in the hub
    motion = interpolate(shaped, times, morris.body.parts, fps=fps, speed=rng.uniform(0.8, 1.25))
    positions = motion.positions + rng.normal(0.0, noise, motion.positions.shape)
    root = morris.body.root_index
    return Motion(positions - positions[:, root : root + 1], fps, morris.body.parts)


def _movement_keys(morris: Any, movement: str) -> tuple[np.ndarray, np.ndarray]:
    m = morris.motor.repertoire[movement]
    return np.stack([morris.motor.key_poses[p] for p in m.poses]), np.asarray(m.times, dtype=float)


def _trial(item: dict[str, Any], pm: Any) -> dict[str, Any]:
    """One (movement, trial): the takes drawn, then for each k Max learns from k of them and watches the tests."""
    rng = np.random.default_rng(item["seed"])
    morris = load_character("morris", pm)
    if item["movement"] == "windmill":
        keys, times = _movement_keys(morris, "windmill")
    else:
        keys, times = _novel(rng, morris)
    kw = {"noise": item["noise"], "jitter": item["jitter"]}
    training = [take(keys, times, morris, rng, **kw) for _ in range(max(item["takes"]))]
    tests = [take(keys, times, morris, rng, **kw) for _ in range(item["tests"])]
    own = [m for m in morris.motor.repertoire if m not in ("stand", "windmill")]
    known = [take(*_movement_keys(morris, str(m)), morris, rng, **kw) for m in rng.choice(own, item["tests"])]
    rows = []
    for k in item["takes"]:
        max_ = load_character("max", pm, override={"motor": {"takes": max(item["takes"])}})  # keeps every take given
        matcher = max_.matcher
        samples = [matcher.samples(t.onto(max_.body.parts))[1] for t in training[:k]]
        max_.motor.learn_takes(NAME, [s[0] for s in samples], [s[1] for s in samples], source="bench", announce=False)
        matcher._refresh()
        answers = [matcher.match(t.onto(max_.body.parts)) for t in tests]
        false = [matcher.match(t.onto(max_.body.parts)).movement == NAME for t in known]
        distances = [float(a.details.get("mean_distance", np.nan)) for a in answers]
        rows.append({"movement": item["movement"], "trial": item["trial"], "k": k,
                     "recognised": sum(a.movement == NAME for a in answers) / len(answers),
                     "unknown": sum(a.movement is None for a in answers) / len(answers),
                     "other": sum(a.movement not in (None, NAME) for a in answers) / len(answers),
                     "false": sum(false) / len(false), "distance": float(np.nanmedian(distances)),
                     "spread": float(max_.motor.learned[NAME]["spread"])})
    return {"rows": rows}


def learning_benchmark(pm: Any, *, takes: tuple[int, ...] = (1, 2, 3, 5), generated: int = 3, trials: int = 5,
                       tests: int = 20, noise: float = 0.005, jitter: float = 0.015, seed: int = 0, jobs: int = 1,
                       scheduler: str | None = None) -> dict[str, Any]:
    """Recognition of held-out takes of new movements learned from k takes, for each k of ``takes`` (the module)."""
    from plugins.bench.jobs import run_with_pm

    movements = ["windmill"] + [f"generated-{i + 1}" for i in range(generated)]
    seeds = np.random.default_rng(seed).integers(1 << 30, size=len(movements) * trials)
    items = [{"movement": m, "trial": t, "seed": int(seeds[i * trials + t]), "takes": sorted(set(takes)),
              "tests": tests, "noise": noise, "jitter": jitter} for i, m in enumerate(movements) for t in range(trials)]
    results = run_with_pm(_trial, items, pm, jobs=jobs, scheduler=scheduler)
    rows = [r for result in results for r in result["rows"]]
    table = {}
    for k in sorted(set(takes)):
        sub = [r for r in rows if r["k"] == k]
        table[k] = {key: float(np.mean([r[key] for r in sub])) for key in ("recognised", "unknown", "other", "false")}
        table[k]["distance"] = float(np.median([r["distance"] for r in sub]))
        table[k]["spread"] = float(np.median([r["spread"] for r in sub]))
    return {"benchmark": "learning", "seed": seed, "movements": movements, "trials": trials, "tests": tests,
            "noise": noise, "jitter": jitter, "table": {str(k): v for k, v in table.items()}, "rows": rows}


def render_learning(r: dict[str, Any]) -> str:
    head = (f"likeme bench learning: new movements learned from k takes ({len(r['movements'])} movements x "
            f"{r['trials']} trials, {r['tests']} test takes each; noise {r['noise']:g} m, jitter {r['jitter']:g} m, "
            f"seed {r['seed']})")
    rows = [[k, f"{t['recognised']:.3f}", f"{t['unknown']:.3f}", f"{t['other']:.3f}", f"{t['false']:.3f}",
             f"{1000 * t['distance']:.1f}", f"{1000 * t['spread']:.1f}"] for k, t in r["table"].items()]
    columns = [("takes", "right")] + [(c, "right") for c in ("recognised", "unknown", "other", "false", "median mm",
                                                               "spread mm")]
    return "\n".join([head, text_table(rows, columns)])


def plot_learning(r: dict[str, Any], out: str | Path) -> Path:
    """Recognised and unknown shares against the number of takes, one line per new movement and the mean."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ks = [int(k) for k in r["table"]]
    for i, m in enumerate(r["movements"]):
        ax.plot(ks, [np.mean([x["recognised"] for x in r["rows"] if x["movement"] == m and x["k"] == k]) for k in ks],
                color="#999999", lw=1, marker=".", label="recognised, each new movement" if i == 0 else None)
    ax.plot(ks, [r["table"][str(k)]["recognised"] for k in ks], color="#1f77b4", lw=2.5, marker="o",
            label="recognised (mean)")
    ax.plot(ks, [r["table"][str(k)]["false"] for k in ks], color="#d62728", lw=2, marker="s",
            label="known movements taken for it")
    ax.set_xlabel("takes the new movement was learned from")
    ax.set_ylabel("share of fresh takes")
    ax.set_xticks(ks)
    ax.set_ylim(-0.02, 1.02)
    ax.legend(loc="center right")
    ax.set_title("A new movement learned from repeated demonstrations (B&B §7.3)", fontsize=10)
    fig.tight_layout()
    from toolkit.files import writing

    try:
        with writing(out, "plot") as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    finally:
        plt.close(fig)
    return Path(out)


def cmd_learning(args: argparse.Namespace, pm: Any) -> int:
    result = learning_benchmark(pm, takes=tuple(args.takes or (1, 2, 3, 5)), generated=args.generated,
                                trials=args.trials, tests=args.tests, noise=args.noise, jitter=args.jitter,
                                seed=args.seed, jobs=args.jobs, scheduler=args.scheduler)
    print(render_learning(result))
    if args.plot:
        print(f"wrote {plot_learning(result, args.plot)}")
    if args.json:
        write_output(args.json, json.dumps(result, indent=2, default=float) + "\n")
    return 0
