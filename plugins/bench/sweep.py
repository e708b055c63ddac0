"""``likeme bench sweep GRID.toml``: a grid of data folders, plugins and parameters through one motion-capture
benchmark (:mod:`plugins.bench.mocap`), one tidy table with a row per cell.

A grid file (paths relative to it; ``docs/scaling.md``)::

    benchmark = "segmentation"            # recognition, segmentation or stream
    [data.generated]                      # one table per data set: body, repertoire, demos, streams
    body = "bench-data/profile.toml"
    streams = "bench-data/streams"
    [plugins]
    segmenters = ["hub-threshold", "velocity-direction"]
    [set]                                 # TABLE.KEY = [values]: the grid is the product of the lists
    "segmenter.floor" = [0.0, 0.1]

Every cell (data set x plugin or pairing x one value of each ``set`` key) is one run of
:func:`plugins.bench.mocap.cell`, through :func:`plugins.bench.jobs.run_items` (``--jobs``, ``--scheduler``), so
the table does not depend on where the cells ran; ``fps`` (frames per second) is the only timing column.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import time
import tomllib
from pathlib import Path
from typing import Any

from plugins.bench import text_table
from plugins.bench.command import MATCHERS, SEGMENTERS
from toolkit import ConfigError
from toolkit.config.toml import MAX_DIGITS, NumberTooLong, loads

__all__ = ["TIMING", "cells", "cmd_sweep", "load_grid", "sweep"]

BENCHMARKS = ("recognition", "segmentation", "stream")
TOP_KEYS = ("benchmark", "data", "plugins", "set", "protocol", "group", "fps", "observer", "correspondence",
            "lengths_for_height")
DATA_KEYS = ("body", "repertoire", "demos", "streams")
PLUGIN_KEYS = ("matchers", "segmenters")
NEEDS = {"recognition": ("body", "repertoire"), "segmentation": ("body", "streams"),
         "stream": ("body", "repertoire", "streams")}
TIMING = ("fps",)
"""The table's timing columns: the only ones that depend on the machine and the number of workers."""


def _unknown(table: dict[str, Any], allowed: tuple[str, ...], file: Path, key: tuple[str, ...]) -> None:
    for k in table:
        if k not in allowed:
            raise ConfigError(f"unknown key {k!r}", file=file, key=(*key, k), expected="a grid key",
                              available=list(allowed))


def _literal(value: Any) -> str:
    """A TOML value written back as the VALUE of ``--set TABLE.KEY=VALUE``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return json.dumps(value)


def load_grid(path: str | Path) -> dict[str, Any]:
    """Read and check a grid file: keys, benchmark, folders (resolved against the grid's folder), plugin lists."""
    path = Path(path)
    try:
        grid = loads(path.read_text(encoding="utf-8"))
    except NumberTooLong as err:
        raise ConfigError(str(err), file=path, line=err.line, column=err.column,
                          expected=f"an integer of at most {MAX_DIGITS} digits") from None
    except FileNotFoundError:
        raise ConfigError("grid file not found", file=path, expected="a GRID.toml (docs/scaling.md)") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise ConfigError(f"not TOML: {err}", file=path, expected="a GRID.toml (docs/scaling.md)") from None
    _unknown(grid, TOP_KEYS, path, ())
    benchmark = grid.get("benchmark")
    if benchmark not in BENCHMARKS:
        raise ConfigError(f"benchmark {benchmark!r}", file=path, key=("benchmark",), expected="a benchmark",
                          available=list(BENCHMARKS))
    data = grid.get("data")
    if not isinstance(data, dict) or not data or not all(isinstance(v, dict) for v in data.values()):
        raise ConfigError("no data sets", file=path, key=("data",),
                          expected="[data.NAME] tables with body, repertoire, demos, streams folders")
    folders = {}
    for name, table in data.items():
        _unknown(table, DATA_KEYS, path, ("data", name))
        for key in NEEDS[benchmark] + (("demos",) if benchmark == "recognition" and
                                       grid.get("protocol", "closed") != "groups" else ()):
            if key not in table:
                raise ConfigError(f"data set {name!r} has no {key}", file=path, key=("data", name, key),
                                  expected=f"the {key} of a {benchmark} benchmark")
        resolved = {}
        for key, value in table.items():
            full = (path.parent / str(value)).resolve()
            if not full.exists():
                raise ConfigError(f"{key} not found: {full}", file=path, key=("data", name, key),
                                  expected="an existing file or folder (relative to the grid file)")
            resolved[key] = str(full)
        folders[name] = resolved
    plugins = grid.get("plugins", {})
    if not isinstance(plugins, dict):
        raise ConfigError("plugins is not a table", file=path, key=("plugins",), expected="[plugins] matchers, "
                          "segmenters")
    _unknown(plugins, PLUGIN_KEYS, path, ("plugins",))
    settings = grid.get("set", {})
    if not isinstance(settings, dict):
        raise ConfigError("set is not a table", file=path, key=("set",), expected='[set] "TABLE.KEY" = [values]')
    for key, values in settings.items():
        if "." not in key or not isinstance(values, list) or not values:
            raise ConfigError(f"set key {key!r}", file=path, key=("set", key),
                              expected='"TABLE.KEY" = [one or more values], like "segmenter.floor" = [0.0, 0.1]')
    observer = grid.get("observer")  # None: the observer template
    if observer is not None and not isinstance(observer, str):
        raise ConfigError(f"observer is {type(observer).__name__}", file=path, key=("observer",),
                          expected="an observer template: a TOML file (relative to the grid file) or the name of one "
                          "in characters/observers/")
    if observer and (path.parent / observer).is_file():
        observer = str((path.parent / observer).resolve())
    return {"file": str(path), "benchmark": benchmark, "data": folders, "observer": observer,
            "matchers": list(plugins.get("matchers", MATCHERS)),
            "segmenters": list(plugins.get("segmenters", SEGMENTERS if benchmark == "segmentation" else
                                                        SEGMENTERS[:2])),
            "set": settings, **{k: grid[k] for k in ("protocol", "group", "fps", "correspondence",
                                                      "lengths_for_height") if k in grid}}


def cells(grid: dict[str, Any]) -> list[dict[str, Any]]:
    """The grid's cells in a fixed order (data set, plugin or pairing, settings): specs of
    :func:`plugins.bench.mocap.cell`, with ``data`` and ``values`` (the cell's ``set`` values) for the table."""
    kind = grid["benchmark"]
    if kind == "recognition":
        plugins = [{"matchers": [m]} for m in grid["matchers"]]
    elif kind == "segmentation":
        plugins = [{"segmenters": [s]} for s in grid["segmenters"]]
    else:
        plugins = [{"segmenters": [s], "matchers": [m]} for s in grid["segmenters"] for m in grid["matchers"]]
    keys = list(grid["set"])
    observer = {"correspondence": grid.get("correspondence", ""),
                "lengths_for_height": grid.get("lengths_for_height", ""),
                "template": grid.get("observer")}
    out = []
    for name, folders in grid["data"].items():
        for plugin in plugins:
            for values in itertools.product(*(grid["set"][k] for k in keys)):
                out.append({"benchmark": kind, "data": name, **{k: None for k in ("repertoire", "demos", "streams")},
                            **folders, **plugin, "observer": observer, "fps": grid.get("fps"),
                            "protocol": grid.get("protocol", "closed"), "group": grid.get("group"),
                            "values": dict(zip(keys, values)),
                            "set": [f"{k}={_literal(v)}" for k, v in zip(keys, values)]})
    return out


def _check(grid: dict[str, Any], pm: Any) -> None:
    """Every ``set`` key and value against every plugin it reaches, before any cell runs."""
    from toolkit.observe import observer_plugins
    from toolkit.config.settings import check_settings, parse_settings

    kind = grid["benchmark"]
    plugins = observer_plugins(pm, segmenters=grid["segmenters"] if kind != "recognition" else (),
                               matchers=grid["matchers"] if kind != "segmentation" else (),
                               correspondence=grid.get("correspondence", ""),
                               template=grid.get("observer"))
    for values in itertools.product(*grid["set"].values()):
        check_settings(parse_settings([f"{k}={_literal(v)}" for k, v in zip(grid["set"], values)]), pm, plugins)


def _row(spec: dict[str, Any], result: dict[str, Any]) -> dict[str, Any]:
    """The tidy row of one cell: what the cell is, then every per-plugin figure (no confusion matrix)."""
    figures = {k: v for k, v in result["plugins"][0].items() if k not in ("plugin", "labels", "confusion")}
    return {"benchmark": spec["benchmark"], "data": spec["data"], "plugin": result["plugins"][0]["plugin"],
            **spec["values"], **figures}


def sweep(grid: dict[str, Any], *, jobs: int = 1, scheduler: str | None = None) -> list[dict[str, Any]]:
    """Run every cell of a grid (:func:`load_grid`); the tidy table, one row per cell, in the cells' order."""
    from plugins.bench.jobs import run_items
    from plugins.bench.mocap import cell

    specs = cells(grid)
    results = run_items(cell, specs, jobs=jobs, scheduler=scheduler)
    return [_row(spec, result) for spec, result in zip(specs, results)]


def _csv(rows: list[dict[str, Any]]) -> str:
    keys = list(dict.fromkeys(k for r in rows for k in r))
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()


def cmd_sweep(args: Any, pm: Any) -> int:
    """``likeme bench sweep GRID.toml [--jobs N] [--scheduler ADDRESS] [--json FILE] [--csv FILE]``."""
    from toolkit.state import write_atomic

    grid = load_grid(args.grid)
    _check(grid, pm)
    start = time.perf_counter()
    rows = sweep(grid, jobs=args.jobs, scheduler=args.scheduler)
    wall = time.perf_counter() - start
    keys = list(dict.fromkeys(k for r in rows for k in r if k != "benchmark"))
    print(text_table([[_text(r.get(k, "")) for k in keys] for r in rows], [(k, "left") for k in keys]))
    where = f"scheduler {args.scheduler}" if args.scheduler else f"{args.jobs} job{'s' if args.jobs > 1 else ''}"
    print(f"\n{len(rows)} cells in {wall:.1f} s wall time ({where})")
    if args.json:
        write_atomic(Path(args.json), json.dumps(rows, indent=1, default=float) + "\n")
    if args.csv:
        write_atomic(Path(args.csv), _csv(rows))
    return 0


def _text(value: Any) -> str:
    """A cell of the printed table; a score that does not apply (NaN) is '-', as in the benchmarks' tables."""
    if isinstance(value, float):
        return "-" if math.isnan(value) else f"{value:.4g}"
    return str(value)
