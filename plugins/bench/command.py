"""The ``likeme bench`` command: one sub-command per benchmark (see :mod:`plugins.bench` and ``docs/benchmarks.md``).

Only the parsers are built here; a benchmark's module is imported when its sub-command runs, so ``likeme`` starts
without the benchmarks' imports.
"""

from __future__ import annotations

import argparse
from importlib import import_module
from typing import Any

from toolkit import hookimpl
from toolkit.arguments import count_type, fps_type, number_type, observer_options, seed_type

MAX_NODES = 500_000
"""The most poses ``likeme bench posegraph --nodes`` builds an index of: half a million poses of the body's 11 parts
take about 0.75 GB with their k-d tree (a million took 1.46 GB); ``--nodes`` times ``--parts`` is held to the same
5.5 million joint positions."""

MATCHERS = ("path-search", "forward-model", "dtw")
"""The matchers ``likeme bench recognition`` and ``stream`` compare when none is named."""
SEGMENTERS = ("hub-threshold", "velocity-direction", "ruptures")
"""The segmenters ``likeme bench segmentation`` compares when none is named (``stream``: the first two)."""


SCRIPT_MAX_RANDOM = 100_000
"""``plugins.action.script.MAX_RANDOM`` written out for ``--help`` (which imports no component module; a test keeps
the two equal)."""


def _movements(text: str) -> int:
    """``bench watch --movements``: an integer in [1, the most a script draws]."""
    from plugins.action.script import MAX_RANDOM

    return count_type(1, MAX_RANDOM)(text)


def _handler(module: str, function: str, *extra: Any):
    """A handler that imports ``plugins.bench.MODULE`` when it runs and calls ``FUNCTION(*extra, args, pm)``; its
    ``--set`` settings are checked first against every plugin they will reach (:func:`_check_set`)."""

    def run(args: argparse.Namespace, pm: Any) -> int:
        if getattr(args, "set", None):
            _check_set(args, pm)
        return getattr(import_module(f"plugins.bench.{module}"), function)(*extra, args, pm)

    return run


def _check_set(args: argparse.Namespace, pm: Any) -> None:
    """``--set TABLE.KEY=VALUE`` checked before anything runs: against the observer's component of each table, and
    against every segmenter and matcher the benchmark compares (a key one of them lacks fails at once, not after
    the others ran)."""
    from toolkit.config.search import load_chain, merge_tables, resolve_file
    from toolkit.config.settings import check_settings, parse_settings

    settings = parse_settings(list(args.set))
    if args.benchmark == "watch":  # a character watching through synthetic vision (plugins/bench/watch.py)
        path = resolve_file(args.observer, None, pm, key=("--observer",))
        base = merge_tables(load_chain(path, pm)[0], {"perception": {"plugin": "synthetic-vision"}})
        plugins = {k: [v["plugin"]] for k, v in base.items() if isinstance(v, dict) and isinstance(v.get("plugin"), str)}
    else:  # an observer composed from the observer template (toolkit.observe.compose_observer)
        from toolkit.observe import observer_plugins

        segmenters = (list(args.segmenter or SEGMENTERS) if args.benchmark == "segmentation" else
                      list(args.segmenter or SEGMENTERS[:2]) if args.benchmark == "stream" else ())
        matchers = list(args.matcher or MATCHERS) if args.benchmark in ("recognition", "stream") else ()
        plugins = observer_plugins(pm, segmenters=segmenters, matchers=matchers,
                                   correspondence=getattr(args, "correspondence", ""),
                                   template=getattr(args, "observer", None))
    check_settings(settings, pm, plugins)


TIMING_NOTE = ("parallel workers share the machine's cores: each item is timed and its memory measured inside the "
               "worker that runs it, but the other workers perturb its timings, so keep the default 1 for figures")
"""What ``--jobs`` says in the ``--help`` of a benchmark whose figures are timings or memory."""


def _protocol(text: str) -> str:
    """``--protocol``: closed, open, groups or takes:N (N >= 1)."""
    name, _, takes = text.partition(":")
    if name in ("closed", "open", "groups") and not takes:
        return text
    if name == "takes" and takes.isdigit() and int(takes) >= 1:
        return f"takes:{int(takes)}"
    raise argparse.ArgumentTypeError(f"{text!r} is not a protocol: closed, open, groups or takes:N (N >= 1 clips of "
                                     "each movement as the repertoire)")


def _scheduler(text: str) -> str:
    """``--scheduler``: ``local:N`` (N >= 1) or an address with a port (``tcp://HOST:PORT``, ``HOST:PORT``); whether
    a scheduler answers there is found when the benchmark connects (``plugins.bench.jobs``)."""
    if text.startswith("local:"):
        if not text[len("local:"):].isdigit() or int(text[len("local:"):]) < 1:
            raise argparse.ArgumentTypeError(f"invalid value {text!r}: expected local:N with N workers, 1 or more")
    elif ":" not in text.split("://")[-1] or not text.split("://")[-1].rsplit(":", 1)[-1].isdigit():
        raise argparse.ArgumentTypeError(f"invalid address {text!r}: expected a Dask scheduler's address with its "
                                         "port, tcp://HOST:PORT (as `dask scheduler` prints it), or local:N")
    return text


def _jobs_options(p: argparse.ArgumentParser, items: str = "", timing: bool = False) -> None:
    """``--jobs N`` and ``--scheduler ADDRESS`` (:func:`plugins.bench.jobs.run_items`; ``docs/scaling.md``);
    ``items`` says what an item of this benchmark is, ``timing`` that its figures are timings or memory."""
    items = f" ({items})" if items else ""
    after = f"; {TIMING_NOTE}" if timing else "; the figures do not depend on N (frames per second aside)"
    p.add_argument("--jobs", type=count_type(1, 1024), default=1, metavar="N",
                   help=f"run the items{items} in N local processes (default: 1, this process){after}")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None, type=_scheduler,
                   help="run the items on a Dask distributed cluster: a scheduler's address (tcp://HOST:8786) or "
                   "local:N for a LocalCluster of N workers (needs likeme[dask]; docs/scaling.md)")


def _common(p: argparse.ArgumentParser) -> None:
    _jobs_options(p)
    p.add_argument("--body", required=True, metavar="PROFILE", help="body profile TOML of the files")
    observer_options(p)
    p.add_argument("--fps", type=fps_type, default=None, metavar="HZ",
                   help="frame rate of the demos, streams and repertoire clips without one of their own (CSV "
                   "without a time column, .npy); wins over the profile's fps; a BVH's Frame Time and a CSV's "
                   "time column win over it")
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.add_argument("--csv", metavar="FILE", help="also write the results as CSV (one row per plugin and per item)")
    p.add_argument("--plot", metavar="PNG", help="draw the results (confusion matrices, scores per plugin)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--jitter", type=number_type(0.0, 1.0, "metres"), default=0.0, metavar="M",
                   help="read every recording (repertoire, demos, streams) with M metres of a tracker's jitter: "
                   "independent Gaussian noise on each coordinate of each joint in each frame, the same for a file "
                   "whatever reads it (plugins.bench.tracker; default 0: as recorded)")
    p.add_argument("--dropout", type=number_type(0.0, 0.5, "share of frames"), default=0.0, metavar="S",
                   help="and lose each joint for S of its frames, in gaps of 0.1-0.33 s (a tracker losing a joint: "
                   "not seen; default 0)")


def _motion_capture_commands(sub: Any) -> None:
    """``recognition``, ``segmentation`` and ``stream`` on motion-capture files, and the data they read."""
    p = sub.add_parser("recognition", help="classify labelled demo clips with every matcher named")
    _common(p)
    p.add_argument("--repertoire", required=True, metavar="DIR", help="labelled clips: one folder per movement")
    p.add_argument("--demos", metavar="DIR", help="demo clips: one folder per true movement (not with --protocol "
                   "groups)")
    p.add_argument("--matcher", action="append", metavar="NAME", help=f"matcher (repeatable; default: {', '.join(MATCHERS)})")
    p.add_argument("--protocol", type=_protocol, default="closed", metavar="{closed,open,groups,takes:N}",
                   help="closed: every demo against the whole repertoire; open: the demos of each movement against "
                   "the repertoire without it (leave one movement out: only 'unknown' is right); groups: each group "
                   "of the repertoire's clips (--group) against a repertoire of the other groups (leave one group "
                   "out: a style, a performer); takes:N: the first N clips of each movement's folder (by name) as the "
                   "repertoire, its other clips and every demo (--demos, optional) as demos")
    p.add_argument("--group", metavar="REGEX", help="with --protocol groups: a regular expression whose first "
                   "capture group, searched in a clip's file name, names its group")
    p.set_defaults(handler=_handler("mocap", "run", "recognition"))

    p = sub.add_parser("segmentation", help="segment streams with known segments with every segmenter named")
    _common(p)
    p.add_argument("--streams", required=True, metavar="DIR", help="NAME.bvh (or .csv, .npy) files with NAME.segments.csv")
    p.add_argument("--repertoire", metavar="DIR", help="clips the hubs are found from (default: the streams' ends)")
    p.add_argument("--segmenter", action="append", metavar="NAME", help=f"segmenter (repeatable; default: {', '.join(SEGMENTERS)})")
    p.set_defaults(handler=_handler("mocap", "run", "segmentation"))

    p = sub.add_parser("stream", help="segment and recognise streams end to end with every pairing")
    _common(p)
    p.add_argument("--repertoire", required=True, metavar="DIR", help="labelled clips: one folder per movement")
    p.add_argument("--streams", required=True, metavar="DIR", help="NAME.bvh (or .csv, .npy) files with NAME.segments.csv")
    p.add_argument("--segmenter", action="append", metavar="NAME", help="segmenter (repeatable)")
    p.add_argument("--matcher", action="append", metavar="NAME", help="matcher (repeatable)")
    p.set_defaults(handler=_handler("mocap", "run", "stream"))

    p = sub.add_parser("sweep", help="a grid of data folders, plugins and parameters through recognition, "
                       "segmentation or stream: one tidy table with every figure (docs/scaling.md)")
    p.add_argument("grid", metavar="GRID.toml", help="the grid: benchmark, data folders, plugins, --set values")
    _jobs_options(p)
    p.add_argument("--json", metavar="FILE", help="also write the table as JSON (a list of rows)")
    p.add_argument("--csv", metavar="FILE", help="also write the table as CSV (one row per cell and plugin)")
    p.set_defaults(handler=_handler("sweep", "cmd_sweep"))

    p = sub.add_parser("make-data", help="write repertoire, demos, streams and a profile from the built-in characters")
    p.add_argument("dest", metavar="DIR")
    _jobs_options(p, "the BVH files, written from motions performed here; the same files whatever N")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--format", choices=("bvh", "csv", "npy", "c3d"), default="bvh",  # plugins.bench.data.FORMATS
                   help="the recordings' format: BVH, CSV joint positions, .npy arrays or C3D markers (default: bvh)")
    p.set_defaults(handler=_handler("data", "cmd_make_data"))

    p = sub.add_parser("make-gestures", help="write hand gestures (waves and raises of the left, right and both "
                       "hands) of several performers in seven styles as a Kinect's tracker records them: "
                       "repertoire, demos and a profile")
    p.add_argument("dest", metavar="DIR")
    _jobs_options(p, "the CSV files, each take drawn here and written by a worker; the same files whatever N")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--performers", type=count_type(1, 100), default=4, help="performers (default: 4); the first "
                   "one's normal style is the repertoire")
    p.add_argument("--takes", type=count_type(1, 100), default=4, help="takes of the repertoire's movements "
                   "(default: 4)")
    p.add_argument("--jitter", type=number_type(0.0, 1.0, "metres"), default=0.01, metavar="M", help="the tracker's "
                   "jitter, twice this at the wrists and hands (default: 0.01)")
    p.add_argument("--lost", type=number_type(0.0, 0.5, "share of joint positions"), default=0.02, metavar="S",
                   help="the share of joint positions lost, in runs of one to four frames (default: 0.02)")
    p.set_defaults(handler=_handler("gestures", "cmd_make_gestures"))

    p = sub.add_parser("bandai", help="build benchmark folders from the Bandai-Namco clips (links; nothing copied): "
                       "streams/ (takes at rest joined through a rest), cropped/ (takes joined end to end), and with "
                       "--locomotion locomotion/")
    p.add_argument("src", metavar="BANDAI_DIR")
    _jobs_options(p, "the streams, each read from its clips and written; the same files whatever N")
    p.add_argument("dest", metavar="DIR")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--profile", default=None, help="the body profile to put beside the data (default: the built-in "
                   "profiles/bandai-namco.toml, from the source tree or the installed copy)")
    p.add_argument("--locomotion", metavar="DIR", default=None, help="also write DIR/locomotion/ from the folder of "
                   "Bandai-Namco dataset-2's locomotion clips (a repertoire of its normal style and streams of the "
                   "others, walks joined without a rest)")
    p.set_defaults(handler=_handler("data", "cmd_bandai"))


@hookimpl
def likeme_register_commands(subparsers):
    bench = subparsers.add_parser("bench", help="measure accuracy and speed (benchmarks)")
    sub = bench.add_subparsers(dest="benchmark", metavar="BENCHMARK", parser_class=type(bench), required=True)
    _motion_capture_commands(sub)

    p = sub.add_parser("watch", help="an observer watches a demonstrator's random movements (B&B §5)")
    _jobs_options(p, "the --runs")
    p.add_argument("--runs", type=count_type(1, 10_000), default=1, metavar="R",
                   help="independent runs, each a fresh world with --movements movements, run r with seed --seed + r; "
                   "the figures pool every run (default: 1)")
    p.add_argument("--observer", default="max", help="observer character (default: max)")
    p.add_argument("--demonstrator", default="morris", help="demonstrator character (default: morris)")
    p.add_argument("--movements", type=_movements, default=200,
                   help=f"number of random movements, at most {SCRIPT_MAX_RANDOM} (default: 200)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--noise", type=number_type(0.0, 1.0, "metres"), default=0.005,
                   help="vision noise, metres (default: 0.005)")
    p.add_argument("--dropout", type=number_type(0.0, 1.0, "a probability"), default=0.05,
                   help="per-part dropout probability (default: 0.05)")
    p.add_argument("--no-occlusion", action="store_true", help="switch occlusion off")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE",
                   help="override an observer parameter, e.g. --set segmenter.floor=0 (repeatable)")
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=_handler("watch", "cmd_watch"))

    p = sub.add_parser("facilitation", help="Max learns Moritz's arm and finger movements and imitates familiar ones early (K&G §4-5)")
    _jobs_options(p, "the --runs")
    p.add_argument("--runs", type=count_type(1, 10_000), default=1, metavar="R",
                   help="independent runs, each a fresh Max who learns his own repertoire, run r with seed --seed + r; "
                   "the figures pool every run's demonstrations (default: 1)")
    p.add_argument("--demonstrations", type=count_type(1, 100_000), default=200,
                   help="demonstrations after the repertoire (default: 200)")
    p.add_argument("--repertoire", type=count_type(1, 100), default=6,
                   help="random movements learned first (default: 6)")
    p.add_argument("--noise", type=number_type(0.0, 1.0, "metres"), default=0.002,
                   help="observation noise, metres (default: 0.002)")
    p.add_argument("--hands", type=number_type(0.0, 1.0, "a share of the demonstrations"), default=0.3,
                   help="share of finger movements of the left hand among the "
                   "demonstrations (default: 0.3; 0: arms only)")
    p.add_argument("--angle-noise", type=number_type(0.0, 1.0, "radians"), default=0.005,
                   help="observation noise on finger joint angles, radians "
                   "(default: 0.005)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=_handler("facilitation", "cmd_facilitation"))

    p = sub.add_parser("behaviour", help="an observer identifies the behaviour, motivation and object of a demonstrator (B&B §6)")
    _jobs_options(p)
    p.add_argument("--episodes", type=count_type(1, 100_000), default=100,
                   help="random episodes per condition (default: 100)")
    p.add_argument("--perception", choices=("own", "synthetic-vision"), default="own", help="Max's perception as "
                   "his file gives it (own: rendered vision) or synthetic vision in its place, the same eye and "
                   "looks (default: own)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--json", metavar="FILE", help="also write the results (every episode) as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=_handler("behaviour", "cmd_behaviour"))

    p = sub.add_parser("learning", help="a new movement learned from one demonstration against one learned from "
                       "several (B&B §7.3): how often fresh takes of it are recognised")
    _jobs_options(p, "one per new movement and trial")
    p.add_argument("--takes", type=count_type(1, 50), action="append", metavar="K",
                   help="takes the movement is learned from, repeatable (default: 1, 2, 3, 5)")
    p.add_argument("--generated", type=count_type(0, 100), default=3, help="generated new movements besides "
                   "Morris's windmill (default: 3)")
    p.add_argument("--trials", type=count_type(1, 1000), default=5, help="trials per new movement (default: 5)")
    p.add_argument("--tests", type=count_type(1, 1000), default=20, help="fresh takes watched per trial (default: 20)")
    p.add_argument("--noise", type=number_type(0.0, 1.0, "metres"), default=0.005,
                   help="observation noise, metres (default: 0.005)")
    p.add_argument("--jitter", type=number_type(0.0, 1.0, "metres"), default=0.015,
                   help="each take's posture offset per part, metres (default: 0.015)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--plot", metavar="PNG", help="also draw recognition against the number of takes")
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.set_defaults(handler=_handler("learning", "cmd_learning"))

    p = sub.add_parser("memory", help="the observer's memory against stream length: a live observer fed for "
                       "--minutes, and likeme observe on generated BVH streams")
    _jobs_options(p, "the live observer and each --observe-minutes stream", timing=True)
    p.add_argument("--minutes", type=number_type(1e-3, 1440.0, "minutes"), default=60.0,
                   help="simulated minutes fed to the live observer "
                   "(default: 60)")
    p.add_argument("--every", type=number_type(1e-3, 1440.0, "minutes"), default=10.0,
                   help="print a line every this many minutes (default: 10)")
    p.add_argument("--fps", type=fps_type, default=120.0, help="frames per second of the streams (default: 120)")
    p.add_argument("--block", type=count_type(1, 100_000), default=120, help="frames a packet for the live observer (default: 120)")
    p.add_argument("--tracemalloc", action="store_true", help="also trace Python allocations (slower)")
    p.add_argument("--no-live", action="store_true", help="skip the live observer")
    p.add_argument("--observe-minutes", type=number_type(1e-3, 600.0, "minutes"), action="append", metavar="MIN", help="also run likeme "
                   "observe on a generated stream this long (repeatable; e.g. 1 and 60)")
    p.add_argument("--limit", type=number_type(0.1, 1024.0, "GB"), default=4.0, help="address space cap of the observe subprocess, GB "
                   "(default: 4)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--segmenter", metavar="NAME", help="the live observer's segmenter (default: the observer "
                   "template's)")
    p.add_argument("--matcher", metavar="NAME", help="the live observer's matcher (default: the template's)")
    p.add_argument("--correspondence", metavar="NAME", default="", help="the live observer's correspondence "
                   "(default: the template's; none: none)")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE",
                   help="override an observer parameter (repeatable)")
    p.set_defaults(handler=_handler("memory", "cmd_memory"))

    p = sub.add_parser("posegraph", help="the k nearest poses of a posegraph of --nodes poses: the spatial index "
                       "(plugins.lib.pose_index) against the exhaustive scan; build time, query time, memory")
    _jobs_options(p, "one per --nodes, a table row each", timing=True)
    p.add_argument("--nodes", type=count_type(1, MAX_NODES), action="append", metavar="N",
                   help="poses in the graph (repeatable, one table row each; default: 100000)")
    p.add_argument("--parts", type=count_type(1, 100), default=None, help="parts per pose (default: the body's, 11)")
    p.add_argument("--k", type=count_type(1, 1000), default=8, help="poses asked for (default: 8, path search's k)")
    p.add_argument("--queries", type=count_type(1, 100_000), default=200, help="observed poses asked (default: 200)")
    p.add_argument("--noise", type=number_type(0.0, 1.0, "metres"), default=0.002,
                   help="noise of the graph's poses, metres per coordinate (default: 0.002)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--no-scan", action="store_true", help="time the index only (no scan, answers not compared)")
    p.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    p.set_defaults(handler=_handler("posegraph_index", "cmd_posegraph"))

    p = sub.add_parser("latency", help="how long after the segmenter closes a segment likeme observe - prints it, "
                       "fed by a frame-paced producer (median and p95)")
    _jobs_options(p, "each feeding of a stream", timing=True)
    p.add_argument("--body", metavar="PROFILE", help="body profile of --streams (default: data made here)")
    p.add_argument("--repertoire", metavar="DIR", help="the observer's clips (with --streams)")
    p.add_argument("--streams", metavar="PATH", help="a BVH stream or a folder of them (default: made here)")
    p.add_argument("--n-streams", type=count_type(1, 100), default=3, dest="n_streams",
                   help="streams made when none are given (default: 3)")
    p.add_argument("--runs", type=count_type(1, 100), default=1, help="times each stream is fed (default: 1)")
    p.add_argument("--fps", type=number_type(1.0, 1000.0, "frames per second"), default=None,
                   help="the producer's frame rate (default: each stream's)")
    p.add_argument("--start", choices=("ready", "now"), default="ready", help="start the frames when observe is "
                   "ready (default) or at once, as a tracker that does not wait")
    p.add_argument("--segmenter", metavar="NAME", help="segmenter (default: the observer template's)")
    p.add_argument("--matcher", metavar="NAME", help="matcher (default: the observer template's)")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--json", metavar="FILE", help="also write the latencies as JSON")
    p.set_defaults(handler=_handler("latency", "cmd_latency"))

    p = sub.add_parser("startup", help="how long likeme takes to start: the medians of likeme --version, --help "
                       "and plugins, each run in a fresh process")
    _jobs_options(p, "the runs: each command once", timing=True)
    p.add_argument("--runs", type=count_type(1, 1000), default=20, help="runs of each command (default: 20)")
    p.add_argument("--json", metavar="FILE", help="also write the times as JSON")
    p.set_defaults(handler=_handler("startup", "cmd_startup"))

    p = sub.add_parser("vision", help="rendered-vision against synthetic-vision on the same frames: agreement, "
                       "position difference, milliseconds per frame")
    _jobs_options(p, "one per --resolution, each stepping the scenario itself", timing=True)
    p.add_argument("--scenario", default="jump_then_cover_face", help="scenario to watch (default: jump_then_cover_face)")
    p.add_argument("--observer", default="max", help="the watching actor (default: max)")
    p.add_argument("--resolution", type=count_type(16, 2048), action="append", help="rendered-vision resolution, repeatable "
                   "(default: 240, 480, 960)")
    p.add_argument("--frames", type=count_type(1, 10_000), default=240, help="frames to compare (default: 240)")
    p.add_argument("--scenarios", action="store_true", help="instead: run every scenario with a watcher (or each "
                   "--scenario-name) with its perception and with synthetic vision, side by side: median seconds "
                   "and whether the conclusions are the same")
    p.add_argument("--scenario-name", action="append", metavar="NAME", help="with --scenarios: this scenario only "
                   "(repeatable)")
    p.add_argument("--repeats", type=count_type(1, 100), default=3, help="with --scenarios: runs of each (default: 3)")
    p.set_defaults(handler=_handler("vision", "cmd_vision"))

    p = sub.add_parser("fuzz", help="mutated real-looking inputs through the commands a user runs: only documented "
                       "errors allowed (docs/robustness.md)")
    _jobs_options(p, "blocks of cases, each through its own worker process; a case is made from its number alone, "
                  "so its outcome does not depend on N, but loaded cores reach --timeout sooner")
    p.add_argument("--n", type=count_type(1, 1_000_000), default=2000, help="number of mutated inputs (default: 2000)")
    p.add_argument("--seed", type=seed_type, default=0, help="seed of the mutations (default: 0)")
    p.add_argument("--targets", default="bvh,toml,profile,scenario,state,csv,npy,c3d,special,bench,output",
                   help="comma-separated: bvh, toml, profile, scenario, state, csv, npy, c3d, special (directories, "
                   "FIFOs, links to unreadable files), bench (hostile option values), output (writes on a full disk) "
                   "(default: all)")
    p.add_argument("--timeout", type=number_type(0.1, 3600.0, "seconds"), default=10.0, help="seconds a case may take (default: 10)")
    p.add_argument("--memory", type=count_type(0, 1_048_576), default=1024, help="address space a case may add to the worker, MB (default: 1024; 0: no limit)")
    p.add_argument("--out", metavar="DIR", dest="out_dir", help="write every failing input and its stderr into this "
                   "folder (created if missing), to replay")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(handler=_handler("fuzz", "cmd_fuzz"))

    p = sub.add_parser("scaling", help="cost against stream length, repertoire size and graph size, with the "
                       "log-log slope of each (1.0 = linear)")
    _jobs_options(p, "each stream length and each repertoire size", timing=True)
    p.add_argument("--fps", type=fps_type, default=30.0, help="frame rate of the streams and clips (default: 30)")
    p.add_argument("--minutes", type=number_type(1e-3, 600.0, "minutes"), action="append", metavar="MIN",
                   help="stream length (repeatable; default: 1, 10, 60)")
    p.add_argument("--movements", type=count_type(1, 100_000), action="append", metavar="N",
                   help="repertoire size (repeatable; default: 5, 50, 500)")
    p.add_argument("--quick", action="store_true", help="small sizes (a test): 0.05-0.2 minutes, 3-12 movements")
    p.add_argument("--seed", type=seed_type, default=0)
    p.add_argument("--segmenter", metavar="NAME", help="the observer's segmenter (default: the observer template's)")
    p.add_argument("--matcher", metavar="NAME", help="the observer's matcher (default: the template's)")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE", dest="settings",
                   help="override an observer parameter, e.g. --set matcher.search=k-best (repeatable; checked "
                   "when the observer is composed)")
    p.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    p.set_defaults(handler=_handler("scaling", "cmd_scaling"))
