"""``likeme bench fuzz``: hostile inputs, made by mutating real-looking files, through the commands a user runs.

The seeds are files the project makes itself (:func:`make_seeds`): BVH files with rotation channels and End Sites
(a small hand-written hierarchy, a skeleton with the Bandai-Namco joint names, and a stream written by the
``make-data`` machinery with a tiny repertoire and its profile), the built-in character and observer TOML files,
the body profiles, the built-in scenarios, a state file written by ``likeme run learn_windmill --save`` and CSV
joint-position files. Case ``i`` of seed ``s`` mutates one seed with :func:`plugins.bench.fuzz_mutate.mutate`
(generator ``numpy.random.default_rng([s, i])``, so any case can be made again alone) and runs it through a command:

- ``bvh``: ``likeme validate F.bvh``, ``likeme validate --body PROFILE F.bvh``, ``likeme observe --body PROFILE
  --repertoire DIR F.bvh``;
- ``toml`` (characters, observer template), ``profile``: ``likeme validate F`` (a profile also ``--body F`` with a
  BVH file it maps, or ``observe --body F``);
- ``scenario``: ``likeme run F --duration 1`` or ``likeme validate F``;
- ``state``: ``likeme run learn_windmill --load F --duration 1``;
- ``csv``: ``toolkit.recordings.positions.read_positions(F, fps=30.0)``;
- ``output``: a command that writes (:data:`OUTPUTS`) on a full disk (one case in two), in a read-only folder (one
  in four: the case's folder and its ``out/`` of mode 0o555, refused to root too by
  :func:`plugins.bench.fuzz_worker.permission_bits_hold`; a run where that cannot be made says so in a note) or with
  room.

Cases run one after another in one long-lived worker process (:mod:`plugins.bench.fuzz_worker`) that calls the
``likeme`` command's ``main`` in-process, each with ``--memory`` MB of address space beyond what the worker holds
when the case begins (``RLIMIT_AS``, set again before every case: a case's budget does not depend on which cases ran
before it in the same worker); the parent kills and restarts it on a timeout or a crash. With ``--jobs N`` (or
``--scheduler``) blocks of cases run in N processes, each with a fuzz worker of its own; the results come back in
the cases' order. Outcomes:

- ``ok``: exit status 0;
- ``documented``: exit status 1 and exactly one ``likeme: error: ...`` line on stderr, no traceback;
- ``traceback``: any other exception or exit status (a crash of the worker included);
- ``hang``: no answer within ``--timeout`` seconds;
- ``memory``: ``MemoryError``, or the worker killed by a signal (the kernel's OOM killer).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plugins.bench.fuzz_worker import OUTCOMES, Worker, classify, command_line
from toolkit.config.search import builtin_characters

__all__ = ["TARGETS", "OUTCOMES", "Case", "Result", "make_seeds", "make_case", "Worker", "classify", "run_fuzz",
           "cmd_fuzz"]

CHARACTERS = builtin_characters()

TARGETS = ("bvh", "toml", "profile", "scenario", "state", "csv", "npy", "c3d", "special", "bench", "output")
"""What can be fuzzed, in the order cases are dealt out."""

BAD = ("traceback", "hang", "memory")
"""The outcomes that make ``likeme bench fuzz`` fail."""

FORMAT = {"bvh": "bvh", "toml": "toml", "profile": "toml", "scenario": "toml", "state": "json", "csv": "csv",
          "npy": "npy", "c3d": "c3d", "special": "special", "bench": "none", "output": "bvh"}
SUFFIX = {"bvh": ".bvh", "toml": ".toml", "json": ".json", "csv": ".csv", "npy": ".npy", "c3d": ".c3d",
          "none": ".txt"}


# -- seeds -----------------------------------------------------------------------------------------------------------


def _hand_bvh() -> str:
    """A small hand-written hierarchy: root with six channels, rotation-only children, End Sites; 12 frames."""
    from toolkit.recordings.bvh import BVH, Joint
    from toolkit.recordings.bvh_writer import format_bvh
    joints = [Joint("hips", -1, (0.0, 0.0, 0.0), ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation",
                                                  "Yrotation")),
              Joint("spine", 0, (0.0, 10.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
              Joint("head", 1, (0.0, 10.0, 0.0), ("Zrotation", "Yrotation", "Xrotation")),
              Joint("head_end", 2, (0.0, 5.0, 0.0), (), True),
              Joint("arm", 1, (5.0, 8.0, 0.0), ("Xrotation", "Yrotation", "Zrotation")),
              Joint("arm_end", 4, (10.0, 0.0, 0.0), (), True)]
    t = np.linspace(0.0, 1.0, 12)[:, None]
    values = np.hstack([t * [1.0, 0.0, 2.0] + [0.0, 90.0, 0.0], np.sin(t * [3.0, 2.0, 1.0]) * 20.0,
                        np.cos(t * [1.0, 2.0, 3.0]) * 10.0, t * [5.0, -5.0, 0.0], t * [0.0, 30.0, 60.0]])
    return format_bvh(BVH(joints, 1.0 / 30.0, values, "hand"))


BANDAI_TREE = (("Hips", None), ("Chest", "Hips"), ("Neck", "Chest"), ("Head", "Neck"), ("UpperArm_L", "Chest"),
               ("LowerArm_L", "UpperArm_L"), ("Hand_L", "LowerArm_L"), ("UpperArm_R", "Chest"),
               ("LowerArm_R", "UpperArm_R"), ("Hand_R", "LowerArm_R"), ("UpperLeg_L", "Hips"),
               ("LowerLeg_L", "UpperLeg_L"), ("Foot_L", "LowerLeg_L"), ("Toes_L", "Foot_L"), ("UpperLeg_R", "Hips"),
               ("LowerLeg_R", "UpperLeg_R"), ("Foot_R", "LowerLeg_R"), ("Toes_R", "Foot_R"))
"""The joints of the Bandai-Namco skeleton that ``characters/profiles/bandai-namco.toml`` maps (End Sites added)."""


def _bandai_bvh(rng: np.random.Generator) -> str:
    """A skeleton with the Bandai-Namco joint names, six channels on every joint, End Sites; 20 frames at 30 fps."""
    from toolkit.recordings.bvh import BVH, Joint
    from toolkit.recordings.bvh_writer import format_bvh
    offsets = {"Chest": (0, 20, 0), "Neck": (0, 25, 0), "Head": (0, 10, 0), "UpperArm_L": (15, 20, 0),
               "UpperArm_R": (-15, 20, 0), "UpperLeg_L": (10, -5, 0), "UpperLeg_R": (-10, -5, 0),
               "Toes_L": (0, -5, 12), "Toes_R": (0, -5, 12)}
    down = {"LowerLeg": (0, -40, 0), "Foot": (0, -40, 0), "LowerArm": (25, 0, 0), "Hand": (22, 0, 0)}
    six = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
    joints, index = [], {}
    ends = {"Head", "Hand_L", "Hand_R", "Toes_L", "Toes_R"}
    for name, parent in BANDAI_TREE:
        off = offsets.get(name) or next((v for k, v in down.items() if name.startswith(k)), (0, 90, 0))
        if name.endswith("_R") and name.startswith(("LowerArm", "Hand")):
            off = (-off[0], off[1], off[2])
        index[name] = len(joints)
        joints.append(Joint(name, index[parent] if parent else -1, tuple(map(float, off)), six))
        if name in ends:
            joints.append(Joint(f"{name}_end", index[name], (0.0, 8.0, 3.0), (), True))
    n = sum(1 for j in joints if not j.end_site)
    base = np.array([j.offset for j in joints if not j.end_site]).reshape(1, n, 3)
    rot = rng.normal(0.0, 10.0, (20, n, 3))
    values = np.concatenate([np.repeat(base, 20, axis=0), rot], axis=2).reshape(20, n * 6)
    return format_bvh(BVH(joints, 1.0 / 30.0, values, "bandai"))


def _absolute_refs(text: str, folder: Path) -> str:
    """A built-in TOML file's relative references (``"../max.toml"``) made absolute, so a copy elsewhere loads."""
    return re.sub(r'"(\.\./[^"]+\.toml)"', lambda m: json.dumps((folder / m.group(1)).resolve().as_posix()), text)


def _positions_csv(names: list[str], positions: np.ndarray, fps: float, with_time: bool) -> str:
    header = [f"{n}_{a}" for n in names for a in "xyz"]
    rows = positions.reshape(len(positions), -1)
    if with_time:
        header = ["time"] + header
        rows = np.hstack([np.arange(len(rows))[:, None] / fps, rows])
    return ",".join(header) + "\n" + "\n".join(",".join(f"{v:.6g}" for v in row) for row in rows) + "\n"


def make_seeds(dest: Path, pm: Any, *, seed: int = 0) -> dict[str, list[dict[str, Any]]]:
    """Write the seed files into ``dest``; return, by target, the seeds (``path`` and what a command needs beside).

    Each seed is a dict with ``path`` (the file to mutate) and, where a command needs them, ``profile`` (a profile
    that maps the BVH file), ``bvh`` (a BVH file a profile maps), ``repertoire`` (a folder of labelled clips).
    """
    from plugins.bench.data import make_data
    from toolkit.recordings.bvh import read_bvh

    main = command_line()

    dest = Path(dest)
    rng = np.random.default_rng(seed)
    seeds: dict[str, list[dict[str, Any]]] = {t: [] for t in TARGETS}
    (dest / "bvh").mkdir(parents=True, exist_ok=True)

    # BVH: a hand-written hierarchy, a Bandai-Namco-like skeleton, a generated stream with its repertoire and profile
    hand = dest / "bvh" / "hand.bvh"
    hand.write_text(_hand_bvh(), encoding="utf-8")
    bandai = dest / "bvh" / "bandai.bvh"
    bandai.write_text(_bandai_bvh(rng), encoding="utf-8")
    bandai_profile = CHARACTERS / "profiles" / "bandai-namco.toml"
    data = make_data(pm, dest / "data", seed=seed, streams=1, per_stream=3)
    repertoire = dest / "repertoire"
    for name in ("bow", "clap", "jump"):
        shutil.copytree(data / "repertoire" / name, repertoire / name, dirs_exist_ok=True)
    stream = dest / "bvh" / "stream.bvh"
    shutil.copyfile(data / "streams" / "stream_1.bvh", stream)
    max_profile = dest / "max-profile.toml"
    shutil.copyfile(data / "profile.toml", max_profile)
    seeds["bvh"] = [{"path": hand},
                    {"path": bandai, "profile": bandai_profile},
                    {"path": stream, "profile": max_profile, "repertoire": repertoire}]
    seeds["bvh"].append(seeds["bvh"][-1])  # the stream twice: the only seed that is also observed
    seeds["profile"] = [{"path": bandai_profile, "bvh": bandai},
                        {"path": max_profile, "bvh": stream, "repertoire": repertoire}]

    # TOML: the built-in characters and observer template; the built-in scenarios
    (dest / "toml").mkdir(exist_ok=True)
    (dest / "scenario").mkdir(exist_ok=True)
    for f in sorted(CHARACTERS.glob("*.toml")) + sorted((CHARACTERS / "observers").glob("*.toml")):
        copy = dest / "toml" / f.name
        copy.write_text(_absolute_refs(f.read_text(encoding="utf-8"), f.parent), encoding="utf-8")
        seeds["toml"].append({"path": copy})
    for f in sorted((CHARACTERS / "scenarios").glob("*.toml")):
        copy = dest / "scenario" / f.name
        copy.write_text(_absolute_refs(f.read_text(encoding="utf-8"), f.parent), encoding="utf-8")
        seeds["scenario"].append({"path": copy})

    # a state file, as a user makes one
    state = dest / "state" / "windmill.json"
    state.parent.mkdir(exist_ok=True)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
        status = main(["run", "learn_windmill", "--save", str(state)])
    if status != 0:
        raise RuntimeError(f"could not write the state seed: {err.getvalue()}")
    seeds["state"] = [{"path": state}]

    # CSV joint positions of the generated stream: with and without a time column
    motion = read_bvh(stream)
    positions, _ = motion.forward_kinematics()
    (dest / "csv").mkdir(exist_ok=True)
    for with_time in (False, True):
        f = dest / "csv" / f"stream{'_time' if with_time else ''}.csv"
        f.write_text(_positions_csv(motion.names, positions, motion.fps, with_time), encoding="utf-8")
        seeds["csv"].append({"path": f})

    # the same positions as a .npy array (its profile names the joints and the rate) and as a C3D file
    from plugins.bench.data import write_positions

    (dest / "npy").mkdir(exist_ok=True)
    (dest / "c3d").mkdir(exist_ok=True)
    array = write_positions(dest / "npy" / "stream.npy", list(motion.names), positions)
    npy_profile = dest / "npy-profile.toml"
    npy_profile.write_text(max_profile.read_text(encoding="utf-8").replace(
        "[profile]\n", f"[profile]\nfps = {motion.fps!r}\njoints = {json.dumps(list(motion.names))}\n", 1),
        encoding="utf-8")
    seeds["npy"] = [{"path": array, "profile": npy_profile, "repertoire": repertoire}]
    markers = write_positions(dest / "c3d" / "stream.c3d", list(motion.names), positions, motion.fps)
    seeds["c3d"] = [{"path": markers, "profile": max_profile, "repertoire": repertoire}]
    seeds["special"] = [{"path": hand}]  # the input is made a special file (SPECIAL_FILES), its content unused
    seeds["bench"] = [{"path": hand}]  # the input is the command line (BENCH_OPTIONS)
    seeds["output"] = [{"path": hand, "state": state}]
    return seeds


# -- cases -----------------------------------------------------------------------------------------------------------


@dataclass
class Case:
    """One mutated input and how it is run."""

    index: int
    target: str
    seed_file: str
    mutations: list[str]
    data: bytes
    name: str
    """The input's file name (in the case folder)."""
    argv: list[str] | None = None
    """The ``likeme`` arguments (``{input}`` stands for the input file), or None for a direct call."""
    call: str | None = None
    """``module:function`` called as ``function(input, fps=30.0)`` instead of a command (the csv target)."""
    special: str | None = None
    """What the input is made instead of a file (:data:`SPECIAL_FILES`), or None."""
    full: bool = False
    """Whether the case runs on a full disk (every write to a file fails: ``RLIMIT_FSIZE`` of 0)."""
    read_only: bool = False
    """Whether the case runs in a read-only folder: the case's folder and its ``out/`` of mode 0o555, which stop root
    too (:func:`plugins.bench.fuzz_worker.permission_bits_hold`)."""

    def command(self) -> str:
        """The command that replays the case from the folder its input was written to."""
        if self.argv is not None:
            return "likeme " + " ".join(_quote(a.replace("{input}", self.name)) for a in self.argv)
        module, function = self.call.split(":")
        return f"python -c 'from {module} import {function}; {function}(\"{self.name}\", fps=30.0)'"


def _quote(arg: str) -> str:
    import shlex

    return shlex.quote(arg)


def _command(target: str, seed: dict[str, Any], rng: np.random.Generator) -> list[str]:
    """The ``likeme`` arguments a user would give with this kind of file."""
    f = "{input}"
    if target == "bvh":
        if "repertoire" in seed:  # observing sizes filters from the frame rate: two in three cases of the stream
            return (["observe", "--body", str(seed["profile"]), "--repertoire", str(seed["repertoire"]), f]
                    if rng.random() < 2 / 3 else ["validate", "--body", str(seed["profile"]), f])
        options = [["validate", f]]
        if "profile" in seed:
            options.append(["validate", "--body", str(seed["profile"]), f])
        return options[int(rng.integers(len(options)))]
    if target == "profile":
        options = [["validate", f], ["validate", "--body", f, str(seed["bvh"])]]
        if "repertoire" in seed:
            options.append(["observe", "--body", f, "--repertoire", str(seed["repertoire"]), str(seed["bvh"])])
        return options[int(rng.integers(len(options)))]
    if target == "scenario":
        return ["run", f, "--duration", _duration(rng)] if rng.random() < 0.75 else ["validate", f]
    if target == "state":
        return ["run", "learn_windmill", "--load", f, "--duration", _duration(rng)]
    if target in ("npy", "c3d"):
        options = [["validate", f], ["validate", "--body", str(seed["profile"]), f],
                   ["observe", "--body", str(seed["profile"]), "--repertoire", str(seed["repertoire"]), f]]
        if target == "npy":
            options[0] = ["validate", "--fps", "30", f]
        return options[int(rng.integers(len(options)))]
    if target == "bench":
        base, option = BENCH_OPTIONS[int(rng.integers(len(BENCH_OPTIONS)))]
        return [*base, option, BENCH_VALUES[int(rng.integers(len(BENCH_VALUES)))]]
    if target == "output":
        return [a.replace("{state}", str(seed["state"])) for a in OUTPUTS[int(rng.integers(len(OUTPUTS)))]]
    return ["validate", f]


BENCH_OPTIONS = (
    (["bench", "vision", "--resolution", "16", "--frames", "2"], "--frames"),
    (["bench", "vision", "--frames", "2"], "--resolution"),
    (["bench", "facilitation", "--demonstrations", "2", "--repertoire", "1"], "--noise"),
    (["bench", "facilitation", "--demonstrations", "2", "--repertoire", "1"], "--hands"),
    (["bench", "facilitation", "--demonstrations", "2", "--repertoire", "1"], "--angle-noise"),
    (["bench", "facilitation", "--demonstrations", "2"], "--repertoire"),
    (["bench", "facilitation", "--repertoire", "1"], "--demonstrations"),
    (["bench", "behaviour"], "--episodes"),
    (["bench", "scaling", "--quick"], "--minutes"),
    (["bench", "scaling", "--quick"], "--movements"),
    (["bench", "scaling", "--quick"], "--fps"),
    (["bench", "posegraph", "--queries", "3", "--no-scan"], "--nodes"),
    (["bench", "posegraph", "--queries", "3", "--no-scan", "--nodes", "200"], "--parts"),
    (["bench", "posegraph", "--queries", "3", "--no-scan", "--nodes", "200"], "--k"),
    (["bench", "memory", "--no-live"], "--minutes"),
    (["bench", "memory", "--no-live"], "--observe-minutes"),
    (["bench", "memory", "--no-live"], "--block"),
    (["bench", "memory", "--no-live"], "--limit"),
    (["bench", "watch", "--movements", "1"], "--runs"),
    (["bench", "learning", "--trials", "1", "--tests", "1"], "--takes"),
    (["bench", "fuzz", "--targets", "none"], "--n"),  # an accepted value ends at once: no such target
    (["bench", "fuzz", "--n", "1", "--targets", "none"], "--timeout"),
    (["bench", "fuzz", "--n", "1", "--targets", "none"], "--memory"),
)
"""The ``likeme bench`` options a case gives a hostile value (the last option given wins), each with options that
keep an accepted value's run short."""
BENCH_VALUES = ("0", "-0", "-1", "-3", "nan", "-nan", "inf", "-inf", "1e999", "1e300", "-1e300", "1e6", "10000000",
                "2147483648", "-2147483649", "99999999999999999999999", "1" + "0" * 5000, "1e-320", "", "abc",
                "\u00b2", "\u0663\u0663\u0663\u0663\u0663\u0663\u0663", "0x10", "1e", "--1", ".", "\x1b[2J")
"""The values given: out of every option's range, not finite, beyond 64 bits, malformed (``²``; seven Arabic-Indic
threes, which ``int`` reads as 3,333,333); none a valid small size (``１``, a full-width one, is a valid 1 and would
run a whole benchmark)."""

OUTPUTS = (
    ["profile", "{input}", "--out", "out/p.toml"],
    ["bench", "posegraph", "--nodes", "200", "--queries", "3", "--no-scan", "--json", "out/p.json"],
    ["run", "learn_windmill", "--duration", "0.2", "--save", "out/s.json"],
    ["run", "learn_windmill", "--duration", "0.2", "--load", "{state}", "--save", "out/s.json"],
    ["bench", "make-data", "out/gen"],
    ["bench", "make-gestures", "out/ges", "--performers", "1", "--takes", "1"],
    ["show", "max", "--view", "posegraph", "--out", "out/g.png"],
    ["show", "max", "--view", "posegraph"],  # into the working folder
)
"""Commands that write a file or a folder (``out/`` or the working folder), run on a full disk (every write to a file
fails) in one case in two, in a read-only folder in one in four."""

SPECIAL_FILES = ("directory", "fifo", "dangling link", "link loop", "link to /proc/self/mem", "link to /dev/zero",
                 "unreadable")
"""What the input of a ``special`` case is instead of a file, named with each format's suffix."""
SPECIAL_COMMANDS = (
    (".bvh", ["validate", "{input}"]), (".csv", ["validate", "{input}"]), (".c3d", ["validate", "{input}"]),
    (".npy", ["validate", "--fps", "30", "{input}"]), (".toml", ["validate", "{input}"]),
    (".json", ["run", "learn_windmill", "--duration", "0.2", "--load", "{input}"]),
    (".toml", ["run", "{input}", "--duration", "0.2"]),
)


def make_special(path: Path, kind: str) -> None:
    """Turn ``path`` (a file just written) into the special file ``kind`` (:data:`SPECIAL_FILES`)."""
    path.unlink(missing_ok=True)
    if kind == "directory":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "dangling link":
        path.symlink_to(path.parent / "nowhere")
    elif kind == "link loop":
        other = path.with_name("loop" + path.suffix)
        other.unlink(missing_ok=True)
        path.symlink_to(other)
        other.symlink_to(path)
    elif kind == "link to /proc/self/mem":
        path.symlink_to("/proc/self/mem")
    elif kind == "link to /dev/zero":
        path.symlink_to("/dev/zero")
    else:
        path.write_bytes(b"x")
        path.chmod(0)


HOSTILE_DURATIONS = ("nan", "inf", "-1", "0", "1e300", "1e-9")
"""What ``--duration`` is, in one case in ten of the scenario and state targets (else 1 second)."""


def _duration(rng: np.random.Generator) -> str:
    return HOSTILE_DURATIONS[int(rng.integers(len(HOSTILE_DURATIONS)))] if rng.random() < 0.1 else "1"


def make_case(index: int, target: str, seeds: dict[str, list[dict[str, Any]]], seed: int) -> Case:
    """Case ``index`` of run ``seed`` for ``target``: the same numbers always give the same input and command."""
    from plugins.bench.fuzz_mutate import mutate

    rng = np.random.default_rng([seed, index, TARGETS.index(target)])
    pool = seeds[target]
    chosen = pool[int(rng.integers(len(pool)))]
    fmt = FORMAT[target]
    if target == "special":
        kind = SPECIAL_FILES[int(rng.integers(len(SPECIAL_FILES)))]
        suffix, argv = SPECIAL_COMMANDS[int(rng.integers(len(SPECIAL_COMMANDS)))]
        return Case(index, target, kind, [kind], b"", f"case{index:05d}{suffix}", argv=list(argv), special=kind)
    if target in ("bench", "output"):
        where = rng.random() if target == "output" else 1.0
        full, read_only = where < 0.5, 0.5 <= where < 0.75
        argv = _command(target, chosen, rng)
        what = ([f"{argv[-2]} {argv[-1]!r}"] if target == "bench" else
                ["full disk" if full else "read-only folder" if read_only else "disk with room"])
        return Case(index, target, Path(chosen["path"]).name, what, Path(chosen["path"]).read_bytes(),
                    f"case{index:05d}.bvh", argv=argv, full=full, read_only=read_only)
    data, applied = mutate(Path(chosen["path"]).read_bytes(), fmt, rng)
    name = f"case{index:05d}{SUFFIX[fmt]}"
    if target == "csv":
        return Case(index, target, Path(chosen["path"]).name, applied, data, name, call="toolkit.recordings.positions:read_positions")
    return Case(index, target, Path(chosen["path"]).name, applied, data, name, argv=_command(target, chosen, rng))


# -- the worker ------------------------------------------------------------------------------------------------------


@dataclass
class Result:
    """What happened to one case."""

    case: Case
    outcome: str
    answer: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0

    def key(self) -> str:
        """What groups equal failures: the exception and where it was raised, or the kind of failure."""
        a = self.answer
        if self.outcome == "hang":
            return f"hang at {a.get('where') or '?'}"
        if a.get("died"):
            return f"worker died ({a['died']})"
        if a.get("exception"):
            return f"{a['exception']} at {a.get('where') or '?'}"
        if self.outcome == "traceback":
            return f"exit status {a.get('rc')!r}, {sum(1 for x in a.get('stderr', '').splitlines() if x.startswith('likeme: error: '))} error lines"
        return self.outcome


# -- the run ---------------------------------------------------------------------------------------------------------


BLOCK = 100
"""Cases a block on a Dask cluster (``--scheduler``): an item of :func:`plugins.bench.jobs.run_items`."""


def run_fuzz(pm: Any, *, n: int = 2000, seed: int = 0, targets: tuple[str, ...] = TARGETS, timeout: float = 10.0,
             memory_mb: int = 1024, out: Path | None = None, progress: Any = None,
             notes: list[str] | None = None, jobs: int = 1, scheduler: str | None = None) -> list[Result]:
    """Make and run ``n`` cases dealt round-robin over ``targets``; return their results in the cases' order.

    ``out``: every case that is not ok or documented is written there (``NAME`` input, ``NAME.stderr`` with the
    command that replays it and what it printed). ``notes`` collects what was skipped and why. ``jobs`` local
    processes or the Dask ``scheduler`` each run blocks of cases through a fuzz worker of their own
    (:func:`_fuzz_block`); a case is made from its number alone, so its outcome does not depend on which ran it
    (only a case near ``timeout`` can, on loaded cores). ``progress(result)`` is called for each case as it ends
    here, for each block's cases as the block comes back from a worker.
    """
    from plugins.bench.jobs import in_process, run_with_pm

    notes = notes if notes is not None else []
    targets = tuple(targets)
    if not targets:
        return []
    from toolkit.files import scratch_folder

    with scratch_folder("likeme-fuzz-") as tmp:
        if out is not None:  # the seeds beside the failing cases, so that their commands replay them
            seeds = _seeds_in(Path(out), pm, seed)
        else:
            seeds = make_seeds(tmp / "seeds", pm, seed=seed)
        if in_process(jobs, scheduler):
            results = _run_cases(list(range(n)), targets, seeds, seed, timeout=timeout, memory_mb=memory_mb, tmp=tmp,
                                 out=out, progress=progress)
            notes.extend(_read_only_notes(results))
            return results
        size = BLOCK if scheduler else -(-n // (2 * jobs))  # locally two blocks a process: a slow block is shared
        items = [{"indices": list(range(i, min(i + size, n))), "targets": targets, "seeds": seeds, "seed": seed,
                  "timeout": timeout, "memory_mb": memory_mb} for i in range(0, n, size)]
        results = []
        for block in run_with_pm(_fuzz_block, items, pm, jobs=jobs, scheduler=scheduler):
            for result in block:
                results.append(result)
                if out is not None and result.outcome in BAD:
                    _keep(result, Path(out))
                if progress is not None:
                    progress(result)
        notes.extend(_read_only_notes(results))
        return results


def _read_only_notes(results: list[Result]) -> list[str]:
    """What to say of the read-only cases whose folder did not hold (a file could be created there): how many, and
    why (the first reason), so that a run where it could not be made is not read as one that tried it."""
    loose = [r for r in results if r.case.read_only and r.answer.get("read_only") not in (None, "held")]
    if not loose:
        return []
    return [f"{len(loose)} of {sum(1 for r in results if r.case.read_only)} read-only cases ran in a folder that "
            f"was not read-only here: {loose[0].answer['read_only']}"]


def _fuzz_block(item: dict[str, Any], pm: Any) -> list[Result]:
    """The cases ``item["indices"]`` in whichever process runs them, through a fuzz worker of its own; on the
    caller's seed files where this process sees them, else on its own (:func:`make_seeds`: the same files)."""
    with tempfile.TemporaryDirectory(prefix="likeme-fuzz-") as tmp:
        seeds = item["seeds"]
        if not all(Path(s["path"]).is_file() for pool in seeds.values() for s in pool):  # another machine
            seeds = make_seeds(Path(tmp) / "seeds", pm, seed=item["seed"])
        return _run_cases(item["indices"], tuple(item["targets"]), seeds, item["seed"], timeout=item["timeout"],
                          memory_mb=item["memory_mb"], tmp=Path(tmp))


def _run_cases(indices: list[int], targets: tuple[str, ...], seeds: dict[str, list[dict[str, Any]]], seed: int, *,
               timeout: float, memory_mb: int, tmp: Path, out: Path | None = None,
               progress: Any = None) -> list[Result]:
    """Make and run the cases ``indices`` one after another through one :class:`Worker` (case folders in ``tmp``)."""
    stream = seeds["bvh"][-1]
    warm = [["validate", str(CHARACTERS / "max.toml")],
            ["observe", "--body", str(stream["profile"]), "--repertoire", str(stream["repertoire"]),
             str(stream["path"])],
            ["run", "learn_windmill", "--load", str(seeds["state"][0]["path"]), "--duration", "0.2"]]
    worker = Worker(memory_mb, warm)
    case_dir = tmp / "case"
    results: list[Result] = []
    try:
        for i in indices:
            case = make_case(i, targets[i % len(targets)], seeds, seed)
            _remove(case_dir)
            case_dir.mkdir()
            (case_dir / case.name).write_bytes(case.data)
            if case.special:
                make_special(case_dir / case.name, case.special)
            if case.target == "output":  # the folder the command writes into is there: the write itself is tried
                (case_dir / "out").mkdir()
            if case.read_only:
                for folder in (case_dir / "out", case_dir):
                    folder.chmod(0o555)
            request = {"cwd": str(case_dir), "input": case.name, "call": case.call, "full": case.full,
                       "read_only": case.read_only,
                       "argv": None if case.argv is None else [a.replace("{input}", case.name) for a in case.argv]}
            started = time.monotonic()
            answer = worker.run(request, timeout)
            result = Result(case, classify(answer), answer, time.monotonic() - started)
            results.append(result)
            if out is not None and result.outcome in BAD:
                _keep(result, Path(out))
            if progress is not None:
                progress(result)
    finally:
        worker.close()
        _remove(case_dir)
    return results


def _remove(folder: Path) -> None:
    """Remove a case's folder, made writable again first (a read-only case's, for a user who is not root)."""
    for path in (folder, folder / "out"):
        if path.is_dir() and not path.is_symlink():
            path.chmod(0o755)
    shutil.rmtree(folder, ignore_errors=True)


def _seeds_in(out: Path, pm: Any, seed: int) -> dict[str, list[dict[str, Any]]]:
    """:func:`make_seeds` into ``out/seeds`` (the old seeds replaced); a failure to write them (a full disk, a
    read-only folder) is one error naming the folder, and no part of them is left."""
    from toolkit.files import write_error

    folder = out.resolve() / "seeds"
    try:
        out.mkdir(parents=True, exist_ok=True)
        shutil.rmtree(folder, ignore_errors=True)
        return make_seeds(folder, pm, seed=seed)
    except OSError as exc:
        shutil.rmtree(folder, ignore_errors=True)
        raise write_error(exc, folder, "fuzz seeds") from None


def _keep(result: Result, out: Path) -> None:
    """Write a failing case's input and its stderr (with the command that replays it) into ``out`` (each file
    written whole or not at all: :func:`toolkit.files.write_output`)."""
    from toolkit.files import write_output

    case = result.case
    write_output(out / case.name, case.data, "failing case")
    a = result.answer
    head = [f"# target: {case.target}; seed file: {case.seed_file}; mutations: {', '.join(case.mutations)}",
            f"# outcome: {result.outcome}: {result.key()}", f"# replay (in this folder): {case.command()}"]
    if a.get("message"):
        head.append(f"# message: {a['message']}")
    write_output(out / f"{case.name}.stderr", "\n".join(head) + "\n" + a.get("stderr", ""), "failing case")


def summary_line(results: list[Result]) -> str:
    """``fuzz: N inputs, T tracebacks, H hangs, M over memory``."""
    count = {o: sum(1 for r in results if r.outcome == o) for o in OUTCOMES}
    return (f"fuzz: {len(results)} inputs, {count['traceback']} tracebacks, {count['hang']} hangs, "
            f"{count['memory']} over memory")


def failures(results: list[Result]) -> list[tuple[str, str, list[Result]]]:
    """The failing cases grouped by target and :meth:`Result.key`, most frequent first."""
    groups: dict[tuple[str, str], list[Result]] = {}
    for r in results:
        if r.outcome in BAD:
            groups.setdefault((r.case.target, r.key()), []).append(r)
    return sorted(((t, k, rs) for (t, k), rs in groups.items()), key=lambda g: (g[0], -len(g[2]), g[1]))


def _out_dir(value: str | None) -> Path | None:
    """``--out DIR``: a folder to write into, created if missing, checked before the run."""
    from toolkit.errors import ConfigError

    if not value:
        return None
    path = Path(value)
    expected = "a folder to write the failing cases into (created if missing)"
    if path.exists() and not path.is_dir():
        raise ConfigError("not a folder", file=path, key=("--out",), expected=expected)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".likeme-probe-"):
            pass
    except OSError as exc:
        raise ConfigError(f"cannot write there ({exc.strerror or exc})", file=path, key=("--out",),
                          expected=expected) from None
    return path


def cmd_fuzz(args: Any, pm: Any) -> int:
    """``likeme bench fuzz``: print a table of outcomes per target, the failures by place, and the closing line."""
    from rich.console import Console
    from rich.progress import Progress
    from rich.table import Table

    from toolkit.errors import ConfigError

    targets = tuple(t.strip() for t in args.targets.split(",") if t.strip())
    unknown = [t for t in targets if t not in TARGETS]
    if unknown or not targets:
        raise ConfigError(f"unknown fuzz target(s) {unknown}" if unknown else "no fuzz target", key=("--targets",),
                          expected="a comma-separated list of targets", available=list(TARGETS))
    out_dir = _out_dir(getattr(args, "out_dir", None))
    console = Console(stderr=True)
    notes: list[str] = []
    with Progress(console=console, transient=True, disable=args.quiet or not console.is_terminal) as bar:  # no blank line
        task = bar.add_task("fuzz", total=args.n)
        results = run_fuzz(pm, n=args.n, seed=args.seed, targets=targets, timeout=args.timeout,
                           memory_mb=args.memory, out=out_dir, notes=notes,
                           progress=lambda r: bar.advance(task), jobs=args.jobs, scheduler=args.scheduler)
    out = Console()
    table = Table(title=f"likeme bench fuzz --n {args.n} --seed {args.seed}")
    table.add_column("target")
    for o in OUTCOMES:
        table.add_column(o, justify="right")
    for t in TARGETS:
        rows = [r for r in results if r.case.target == t]
        if rows:
            table.add_row(t, *(str(sum(1 for r in rows if r.outcome == o)) for o in OUTCOMES))
    table.add_row("all", *(str(sum(1 for r in results if r.outcome == o)) for o in OUTCOMES), style="bold")
    out.print(table)
    groups = failures(results)
    if groups:
        print("failures by target and place (count; first case: mutations; command):")
        for target, key, rs in groups:
            first = rs[0]
            print(f"  {target:<8} {len(rs):4d}  {key}\n      {first.case.name}: {', '.join(first.case.mutations)}; "
                  f"{first.case.command()}")
    for note in notes:
        print(f"note: {note}")
    if out_dir is not None:
        print(f"failing inputs, their stderr and the seeds they came from: {out_dir}")
    print(summary_line(results))
    return 1 if any(r.outcome in BAD for r in results) else 0
