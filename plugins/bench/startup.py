"""``likeme bench startup``: how long the ``likeme`` command takes to start.

Each command (``likeme --version``, ``likeme --help``, ``likeme plugins``, ``likeme plugins --params``) is run ``--runs`` times in a fresh
process, the commands taking turns so that a change in the machine's load falls on all of them alike; the wall time
of each run is measured from here (process start to exit) and the median printed with the fastest and slowest. The
machine's load average is printed too: on a shared machine it is the first thing the figures depend on.

Each timed round (every command once) is an item of ``--jobs`` / ``--scheduler`` (:func:`plugins.bench.jobs.
run_items`), timed in the worker that runs it; parallel rounds share the machine's cores, so the default is one
round after another here.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from toolkit.errors import LikemeError

COMMANDS: tuple[tuple[str, ...], ...] = (("--version",), ("--help",), ("plugins",), ("plugins", "--params"))
"""What is timed: the version, the help (the parser), the listing of the plugins (from its cache after the warm-up
round: ``likeme.cli.plugins``), and a command that loads every plugin (the listing with the parameters, never
cached)."""


def likeme_command() -> list[str]:
    """How to start likeme: the ``likeme`` script installed beside this Python, else ``python -m likeme``."""
    script = Path(sys.executable).with_name("likeme")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "likeme"]


def time_commands(runs: int, command: list[str] | None = None, *, jobs: int = 1,
                  scheduler: str | None = None) -> list[dict[str, Any]]:
    """Wall times (s) of every command of :data:`COMMANDS`, ``runs`` each, in turns after one untimed warm-up round
    here (which fills the file cache and Python's bytecode cache); each timed round is an item of
    :func:`plugins.bench.jobs.run_items` (``jobs`` local processes or the Dask ``scheduler``)."""
    from plugins.bench.jobs import run_items

    command = command or likeme_command()
    _round(command)
    rounds = run_items(_round, [command] * runs, jobs=jobs, scheduler=scheduler)
    times = {argv: [r[i] for r in rounds] for i, argv in enumerate(COMMANDS)}
    return [{"command": "likeme " + " ".join(argv), "runs": runs, "median_s": statistics.median(t),
             "min_s": min(t), "max_s": max(t)} for argv, t in times.items()]


def _round(command: list[str]) -> list[float]:
    """The wall time (s) of each command of :data:`COMMANDS` run once with ``command``, in turn."""
    times = []
    for argv in COMMANDS:
        start = time.perf_counter()
        result = subprocess.run([*command, *argv], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        elapsed = time.perf_counter() - start
        if result.returncode != 0:
            raise LikemeError(f"'likeme {' '.join(argv)}' exited with status {result.returncode}: "
                              f"{result.stderr.strip()[-300:]}")
        times.append(elapsed)
    return times


def cmd_startup(args: argparse.Namespace, pm: Any) -> int:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    command = likeme_command()
    rows = time_commands(args.runs, command, jobs=args.jobs, scheduler=args.scheduler)
    load_after = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{' '.join(command)}: {args.runs} runs each; {os.cpu_count()} cores, load average {load:.2f} before, "
          f"{load_after:.2f} after")
    print(f"{'command':<24} {'median ms':>10} {'min ms':>8} {'max ms':>8}")
    for r in rows:
        print(f"{r['command']:<24} {r['median_s'] * 1000:10.0f} {r['min_s'] * 1000:8.0f} {r['max_s'] * 1000:8.0f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"load_average": [load, load_after], "rows": rows}, indent=1) + "\n")
    return 0
