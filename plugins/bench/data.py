"""The folders the motion-capture benchmarks read, written from the project's own characters or from Bandai-Namco clips.

- ``make_data``: ``repertoire/NAME/max.bvh`` (Max's own movements), ``demos/NAME/morris_S.bvh`` (Morris's versions
  at three speeds, with noise), ``streams/stream_K.bvh`` with ``stream_K.segments.csv``, and ``profile.toml``;
- ``bandai``: the same layout from the Bandai-Namco clips (links and generated streams; nothing is copied): streams
  of takes that begin and end at rest joined through a rest, the cropped takes joined end to end (a harder set), and
  locomotion streams (:mod:`plugins.bench.joins`);
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from toolkit import ConfigError
from toolkit.recordings.segments import segments_of, write_segments

__all__ = ["make_data", "bandai", "write_positions", "convert_recordings", "FORMATS"]


def make_data(pm, dest: Path, *, seed: int = 0, streams: int = 6, per_stream: int = 6, noise: float = 0.003,
              fmt: str = "bvh", jobs: int = 1, scheduler: str | None = None) -> Path:
    """Write a benchmark folder from the project's own characters.

    ``repertoire/NAME/max.bvh``: Max's own movements; ``demos/NAME/morris_S.bvh``: Morris's versions of them at
    speeds 0.8, 1.0 and 1.25 with observation noise; ``streams/stream_K.bvh`` with ``.segments.csv``: Morris's
    movements one after another from his rest pose; ``profile.toml``: the body profile (metres, +y up). ``fmt``
    ``"csv"`` or ``"npy"``: the same recordings as joint positions (:func:`convert_recordings`).

    Every movement is performed and every noise drawn here, in order; the BVH files are then written as items of
    :func:`plugins.bench.jobs.run_items` (``jobs`` local processes or the Dask ``scheduler``), the same files
    whatever wrote them.
    """
    if fmt not in FORMATS:
        raise ConfigError(f"unknown format {fmt!r}", key=("--format",), expected="a recording format",
                          available=FORMATS)
    from plugins.bench.jobs import run_items
    from toolkit import load_character
    from toolkit.config.search import resolve_file
    from toolkit.motion import Motion, concatenate

    rng = np.random.default_rng(seed)
    max_c = load_character(resolve_file("max.toml", None, pm), pm)
    morris = load_character(resolve_file("morris.toml", None, pm), pm)
    body = max_c.body
    root = body.root_index
    order = [root] + [i for i in range(body.n_parts) if i != root]
    names = [body.parts[i] for i in order]
    parents = [-1] + [0] * (len(order) - 1)
    files: list[dict] = []

    def save(motion, path: Path, jitter: float = 0.0) -> None:
        positions = motion.positions[:, order] + rng.normal(0.0, jitter, motion.positions.shape) if jitter else \
            motion.positions[:, order]
        files.append({"path": str(path), "names": names, "parents": parents, "positions": positions,
                      "fps": motion.fps})

    dest = Path(dest)
    movements = [m for m in max_c.motor.movements() if m in morris.motor.movements()]
    for m in movements:
        save(max_c.motor.perform(m, fps=30.0), dest / "repertoire" / m / "max.bvh")
        for speed in (0.8, 1.0, 1.25):
            save(morris.motor.perform(m, fps=30.0, speed=speed), dest / "demos" / m / f"morris_{speed}.bvh", noise)
    rest = morris.motor.rest_pose()
    for k in range(streams):
        pieces, rows, at = [], [], 0
        for m in rng.choice(movements, per_stream):
            still = int(rng.integers(10, 30))
            pieces.append(Motion(np.repeat(rest[None], still, axis=0), 30.0, body.parts))
            motion = morris.motor.perform(str(m), fps=30.0, speed=float(rng.choice([0.8, 1.0, 1.25])))
            pieces.append(motion)
            rows.append((at + still, at + still + motion.n_frames, str(m)))
            at += still + motion.n_frames
        pieces.append(Motion(np.repeat(rest[None], 15, axis=0), 30.0, body.parts))
        save(concatenate(pieces), dest / "streams" / f"stream_{k + 1}.bvh", noise)
        (dest / "streams").mkdir(parents=True, exist_ok=True)
        write_segments(segments_of(dest / "streams" / f"stream_{k + 1}.bvh"), rows)
    run_items(_write_recording, files, jobs=jobs, scheduler=scheduler)
    parts = "\n".join(f'{p} = "{p}"' for p in body.parts)
    f = body.facing
    facing = f'left = "{f.left}"\nright = "{f.right}"' + (f'\nforward = "{f.forward}"' if f.forward else "")
    bones = json.dumps([list(b) for b in body.bones])  # Max's, so views draw the skeleton (a TOML array as JSON)
    (dest / "profile.toml").write_text(f'bones = {bones}\n\n[profile]\nname = "max"\nunits = "metre"\nup = "+y"\n\n'
                                       f"[parts]\n{parts}\n\n[facing]\n{facing}\n", encoding="utf-8")
    return convert_recordings(dest, fmt)


def _write_recording(item: dict[str, Any]) -> str:
    """One BVH file of :func:`make_data`: ``item["positions"]`` of the joints ``item["names"]``."""
    from toolkit.recordings.bvh_writer import from_joint_positions, write_bvh

    path = Path(item["path"])
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bvh(from_joint_positions(item["names"], item["parents"], item["positions"], item["fps"]), path)
    return item["path"]


FORMATS = ("bvh", "csv", "npy", "c3d")
"""The recording formats ``likeme bench make-data --format`` writes."""


def write_positions(path: Path, names: list[str], positions: np.ndarray, fps: float | None = None) -> Path:
    """Joint positions (F, J, 3) as a recording :mod:`toolkit.recordings` reads, by the suffix of ``path``.

    ``.csv``: a header ``JOINT_x,JOINT_y,JOINT_z...`` (and ``time`` first when ``fps`` is given: frame k at k / fps
    seconds), numbers written exactly (shortest round-trip form), NaN as an empty cell; ``.npy``: the array;
    ``.c3d``: 3D points labelled with the joint names at ``fps`` (required), as C3D stores them (32-bit floats), NaN
    as a point not reconstructed (residual -1).
    """
    path = Path(path)
    positions = np.asarray(positions, dtype=float)
    if path.suffix.lower() == ".npy":
        np.save(path, positions)
        return path
    if path.suffix.lower() == ".c3d":
        import c3d

        if fps is None:
            raise ValueError("a C3D file needs a frame rate")
        writer = c3d.Writer(point_rate=float(fps), point_units="m   ")
        writer.set_point_labels(list(names))
        missing = ~np.isfinite(positions).all(axis=-1)
        points = np.zeros((*positions.shape[:2], 5), dtype=np.float32)
        points[..., :3] = np.where(missing[..., None], 0.0, positions)
        points[..., 3] = np.where(missing, -1.0, 0.0)
        writer.add_frames([(frame, np.zeros((0, 0), dtype=np.float32)) for frame in points])
        with open(path, "wb") as handle, warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "no analog data": a marker file has none
            writer.write(handle)
        return path
    rows = positions.reshape(len(positions), -1)
    header = [f"{n}_{a}" for n in names for a in "xyz"]
    if fps is not None:
        header.insert(0, "time")
        rows = np.column_stack([np.arange(len(rows)) / fps, rows])
    lines = [",".join(header)]
    lines += [",".join("" if not np.isfinite(v) else repr(float(v)) for v in row) for row in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def convert_recordings(folder: Path, fmt: str, *, time: bool = False) -> Path:
    """Every ``.bvh`` file under ``folder`` replaced by the same joint positions as ``.csv``, ``.npy`` or ``.c3d``.

    The positions are the BVH file's (forward kinematics of what the file holds), so a body profile reads the same
    motion from either. ``time``: a CSV gets a time column (else the frame rate goes in ``profile.toml``). The
    ``profile.toml`` beside them gets ``fps`` (and ``joints``, the arrays' joint order, for ``.npy``).
    """
    from toolkit.recordings.bvh import read_bvh

    folder = Path(folder)
    if fmt not in FORMATS:
        raise ConfigError(f"unknown format {fmt!r}", key=("--format",), expected="a recording format",
                          available=FORMATS)
    if fmt == "bvh":
        return folder
    fps = names = None
    for path in sorted(folder.rglob("*.bvh")):
        bvh = read_bvh(path)
        fps, names = bvh.fps, bvh.names
        write_positions(path.with_suffix("." + fmt), names, bvh.positions(),
                        fps if (time and fmt == "csv") or fmt == "c3d" else None)
        path.unlink()
    profile = folder / "profile.toml"
    if profile.is_file() and fps is not None:
        extra = f"fps = {fps!r}\n" + (f"joints = {json.dumps(names)}\n" if fmt == "npy" else "")
        text = profile.read_text(encoding="utf-8").replace("[profile]\n", "[profile]\n" + extra, 1)
        profile.write_text(text, encoding="utf-8")
    return folder


LOCOMOTION = ("walk", "run", "dash", "walk-back", "walk-left", "walk-right", "dance-short", "dance-long")
"""Dataset-1's contents that never come back to a standing pose (left out of the gesture streams)."""

REST_HOLD = (0.25, 0.75)
"""Seconds (the least and the most, drawn uniformly) a take's last pose is held before the transition to the next
take, and the next take's first pose after it, in the rest-joined streams."""
TRANSITION = 0.5
"""Seconds of the minimum-jerk transition from one take's last pose to the next take's first (rest-joined
streams), at least: longer where a joint has farther to go than :data:`PACE` allows."""
PACE = 1.0
"""Body sizes a second (on average; 1.9 at the peak of a minimum-jerk move) the joint that goes farthest covers in
a transition between two takes: a relaxed arm's pace (0.45 m/s on an adult), not a gesture's."""
STRIDE = 0.2
"""Seconds of the transition between two locomotion takes (no hold: the walk goes on)."""
LEAD = 1.0
"""Seconds of the first pose before a rest-joined stream's first take and of the last after its last."""


def bandai(src: Path, dest: Path, profile_path: Path, *, seed: int = 0, streams: int = 12, per_stream: int = 5,
           gestures_only: bool = True, locomotion: Path | None = None, jobs: int = 1,
           scheduler: str | None = None) -> Path:
    """Benchmark folders from the Bandai-Namco clips (links and generated streams; nothing is copied).

    ``repertoire/``: the normal-style clips; ``demos/``: every other style of the movements the repertoire has;
    ``all/``: every style of those movements, for leave one style out (``likeme bench recognition --repertoire
    DIR/all --protocol groups --group STYLE_PATTERN``, :data:`STYLE_PATTERN`). Two sets of segmentation streams,
    ``per_stream`` demos (other styles than the repertoire's) in each, with their segments:

    - ``streams/``, the set to trust: only takes that begin and end at rest (:func:`plugins.bench.joins.at_rest`, a
      rule, not a choice by hand), joined through a rest as a person performs one after another
      (:func:`plugins.bench.joins.join`): the last pose held :data:`REST_HOLD` seconds, a minimum-jerk transition
      of :data:`TRANSITION` seconds or more (at :data:`PACE`) to the next take's first pose (the take moved to
      stand where the last one stood, facing its way), that pose held again; :data:`LEAD` seconds of rest before
      the first and after the last;
    - ``cropped/``, the harder set (the streams of the releases before): any gesture demo, the takes joined end to
      end as they were cropped, so most joins are jumps at full speed in another stance, which no segmenter that
      looks for rest can cut.

    ``locomotion``: the folder of Bandai-Namco dataset-2's locomotion clips; if given, ``locomotion/repertoire/``
    (its normal style) and ``locomotion/streams/`` (other styles, 4 takes a stream joined by :data:`STRIDE` s
    transitions without a hold: the walk never rests) are written too. Locomotion (:data:`LOCOMOTION`) never
    returns to a standing pose, so the gesture streams hold gestures only unless ``gestures_only`` is false.

    Each stream's clips are drawn here, one stream after another; the streams are then read and written as items
    of :func:`plugins.bench.jobs.run_items` (``jobs`` local processes or the Dask ``scheduler``), the same files
    whatever wrote them.
    """
    from plugins.bench.jobs import run_items

    src, dest = Path(src), Path(dest)
    clips = _takes(src, "dataset-1_*.bvh", "dataset-1_{content}_{style}_{take}.bvh files")
    known = _link_repertoire(clips, dest, with_all=True)
    pool = [p for (c, s), ps in clips.items() if s != "normal" and c in known and
            (c not in LOCOMOTION or not gestures_only) for p in ps]
    if len(pool) < per_stream:
        raise ConfigError(f"{len(pool)} demos of the repertoire's movements in other styles than normal", file=src,
                          expected=f"at least {per_stream} (a stream joins {per_stream} demos, each once)",
                          available=[p.name for p in pool])
    rng = np.random.default_rng(seed)
    items = [{"clips": [str(pool[i]) for i in rng.choice(len(pool), per_stream, replace=False)],
              "path": str(dest / "cropped" / f"stream_{k + 1:02d}.bvh")} for k in range(streams)]
    from plugins.bench.joins import at_rest
    from toolkit.recordings.bvh import read_bvh

    resting = [p for p in pool if at_rest(read_bvh(p))]
    if len(resting) < per_stream:
        raise ConfigError(f"{len(resting)} demos begin and end at rest", file=src,
                          expected=f"at least {per_stream} (--per-stream) for the rest-joined streams",
                          available=[p.name for p in resting])
    items += [{**_joined(rng, resting, per_stream, dest / "streams" / f"stream_{k + 1:02d}.bvh", REST_HOLD,
                         TRANSITION, LEAD), "pace": PACE} for k in range(streams)]
    if locomotion is not None:
        walks = _takes(Path(locomotion), "dataset-2_*.bvh", "dataset-2_{content}_{style}_{take}.bvh files")
        _link_repertoire(walks, dest / "locomotion")
        pool = [p for (c, s), ps in walks.items() if s != "normal" for p in ps]
        if len(pool) < 2:
            raise ConfigError(f"{len(pool)} locomotion takes in other styles than normal", file=locomotion,
                              expected="at least 2 (a locomotion stream joins up to 4 takes)",
                              available=[p.name for p in pool])
        items += [_joined(rng, pool, min(4, len(pool)), dest / "locomotion" / "streams" / f"stream_{k + 1:02d}.bvh",
                          (0.0, 0.0), STRIDE, 0.0) for k in range(max(1, streams // 2))]
    for item in items:
        Path(item["path"]).parent.mkdir(parents=True, exist_ok=True)
    run_items(_bandai_stream, items, jobs=jobs, scheduler=scheduler)
    text = Path(profile_path).read_text(encoding="utf-8")
    for folder in [dest] + ([dest / "locomotion"] if locomotion is not None else []):
        (folder / "profile.toml").write_text(text, encoding="utf-8")
    return dest


def _takes(src: Path, pattern: str, expected: str) -> dict[tuple[str, str], list[Path]]:
    """The clips of a Bandai-Namco folder by (content, style), from their names."""
    files = sorted(src.glob(pattern))
    if not files:
        raise ConfigError("no Bandai-Namco clips", file=src, expected=expected)
    clips: dict[tuple[str, str], list[Path]] = {}
    for f in files:
        _, content, style, _ = f.stem.split("_")
        clips.setdefault((content, style), []).append(f)
    return clips


def _link_repertoire(clips: dict[tuple[str, str], list[Path]], dest: Path, with_all: bool = False) -> set[str]:
    """Links: ``repertoire/CONTENT/`` the normal style, ``demos/CONTENT/`` the others of the contents the repertoire
    has (and ``all/CONTENT/`` every style of them); the contents."""
    known = {c for c, s in clips if s == "normal"}
    for (content, style), paths in clips.items():
        if content not in known:
            continue
        for p in paths:
            folders = [dest / ("repertoire" if style == "normal" else "demos")] + ([dest / "all"] if with_all else [])
            for target in (folder / content / p.name for folder in folders):
                target.parent.mkdir(parents=True, exist_ok=True)
                if not target.exists():
                    target.symlink_to(p.resolve())
    return known


def _joined(rng: np.random.Generator, pool: list[Path], count: int, path: Path, hold: tuple[float, float],
            move: float, lead: float) -> dict[str, Any]:
    """One rest-joined (or locomotion) stream's item: ``count`` takes of ``pool`` drawn without replacement, the
    holds between them drawn in seconds from ``hold``, ``move`` seconds of transition, ``lead`` seconds of rest at
    each end."""
    chosen = [str(pool[i]) for i in rng.choice(len(pool), count, replace=False)]
    holds = rng.uniform(hold[0], hold[1], size=(count - 1, 2)).round(3).tolist()
    return {"clips": chosen, "path": str(path), "holds": holds, "move": move, "lead": lead}


def _bandai_stream(item: dict[str, Any]) -> str:
    """One stream of :func:`bandai`: the clips ``item["clips"]`` one after another, written to ``item["path"]``
    with its ``.segments.csv`` beside it; joined end to end, or through :func:`plugins.bench.joins.join` when the
    item has ``holds`` (seconds before and after each transition), ``move`` (seconds of transition) and ``lead``."""
    from toolkit.recordings.bvh import BVH, read_bvh
    from toolkit.recordings.bvh_writer import write_bvh

    chosen = [Path(p) for p in item["clips"]]
    parts = [read_bvh(p) for p in chosen]
    first = parts[0]
    for p, b in zip(chosen, parts):
        if [(j.name, j.channels) for j in b.joints] != [(j.name, j.channels) for j in first.joints]:
            raise ConfigError("another skeleton than the stream's first take", file=p,
                              expected=f"the joints and channels of {chosen[0].name}")
    labels = [p.stem.split("_")[1] for p in chosen]
    if "holds" in item:
        from plugins.bench.joins import join

        frames = lambda seconds: int(round(seconds * first.fps))  # noqa: E731
        values, rows = join(parts, labels, [(frames(a), frames(b)) for a, b in item["holds"]],
                            [frames(item["move"])] * (len(parts) - 1), frames(item["lead"]), frames(item["lead"]),
                            pace=item.get("pace", 0.0))
    else:
        rows, at = [], 0
        for label, b in zip(labels, parts):
            rows.append((at, at + b.n_frames, label))
            at += b.n_frames
        values = np.concatenate([b.values for b in parts])
    path = Path(item["path"])
    write_bvh(BVH(first.joints, first.frame_time, values, "stream"), path)
    write_segments(segments_of(path), rows)
    return item["path"]


STYLE_PATTERN = r"^dataset-1_[^_]+_([^_]+)_"
"""The style in a Bandai-Namco clip's name (``dataset-1_{content}_{style}_{take}.bvh``), for ``--group``."""


def cmd_make_data(args, pm) -> int:
    """``likeme bench make-data DIR``: written to a staging folder inside DIR and moved into it when complete
    (:func:`toolkit.files.writing_folder`): a full disk leaves no half-written data set."""
    from toolkit.files import writing_folder

    with writing_folder(args.dest, "benchmark data") as stage:
        make_data(pm, stage, seed=args.seed, fmt=getattr(args, "format", "bvh"), jobs=args.jobs,
                  scheduler=args.scheduler)
    print(Path(args.dest))
    return 0


def cmd_bandai(args, pm) -> int:
    """``likeme bench bandai SRC DIR``."""
    from toolkit.config.search import resolve_file

    profile = Path(args.profile) if args.profile else resolve_file("profiles/bandai-namco.toml", None, pm,
                                                                   key=("--profile",))
    from toolkit.files import writing_folder

    with writing_folder(args.dest, "benchmark data") as stage:
        bandai(Path(args.src), stage, profile, seed=args.seed, jobs=args.jobs, scheduler=args.scheduler,
               locomotion=Path(args.locomotion) if args.locomotion else None)
    print(Path(args.dest))
    return 0
