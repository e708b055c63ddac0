"""``--jobs N`` and ``--scheduler ADDRESS`` on every ``likeme bench`` sub-command: the same figures whatever ran
the items (timings aside), bad values refused (see also tests/plugins/bench/test_sweep.py and the rows of tests/likeme/test_errors.py).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

from plugins.bench.command import TIMING_NOTE
from plugins.bench.jobs import run_with_pm
from likeme.cli import main
from toolkit.manager import create_plugin_manager

SUB_COMMANDS = ("recognition", "segmentation", "stream", "sweep", "make-data", "make-gestures", "bandai", "watch",
                "facilitation", "memory", "posegraph", "startup", "vision", "fuzz", "scaling", "behaviour", "learning",
                "latency")
"""Every ``likeme bench`` sub-command (a test checks the list against the command's own)."""
TIMED = ("memory", "posegraph", "startup", "vision", "scaling", "latency")
"""The sub-commands whose figures are timings or memory."""


def _help(name: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        main(["bench", name, "--help"])
    return " ".join(out.getvalue().split())


def _json(path: Path):
    return json.loads(path.read_text())


def _without(value, keys: set[str]):
    """``value`` with every dict key in ``keys`` dropped, at any depth (the timings)."""
    if isinstance(value, dict):
        return {k: _without(v, keys) for k, v in value.items() if k not in keys}
    if isinstance(value, list):
        return [_without(v, keys) for v in value]
    return value


def _dask():
    pytest.importorskip("dask.distributed", reason="dask.distributed not installed: pip install 'likeme[dask]'")


@pytest.mark.parametrize("name", SUB_COMMANDS)
def test_every_sub_command_takes_jobs_and_scheduler(name):
    text = _help(name)
    assert "--jobs N" in text and "--scheduler ADDRESS" in text and "local:N" in text
    assert (" ".join(TIMING_NOTE.split()) in text) == (name in TIMED)


def test_the_list_is_every_sub_command_of_bench():
    from likeme.cli import build_parser
    from toolkit.manager import create_plugin_manager

    def choices(parser):
        (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        return action.choices

    bench = choices(build_parser(create_plugin_manager()))["bench"]
    assert set(choices(bench)) == set(SUB_COMMANDS)


def _square(item, pm):
    """A worker's item: it gets a plugin manager of its own."""
    return item * item if pm.get_plugins() else None


def test_run_with_pm_gives_the_callers_manager_here_and_keeps_the_order():
    pm = create_plugin_manager(autoload=False)
    seen = []
    assert run_with_pm(lambda item, p: seen.append(p) or -item, [3, 1, 2], pm) == [-3, -1, -2]
    assert all(p is pm for p in seen)
    assert run_with_pm(_square, [3, 1, 2], pm, jobs=2) == [9, 1, 4]


WATCH_TIMING = {"seconds", "frames_per_second", "real_time_factor", "wall_s", "jobs", "scheduler"}


def _watch(tmp_path: Path, name: str, *options: str) -> dict:
    out = tmp_path / f"{name}.json"
    assert main(["bench", "watch", "--movements", "3", "--runs", "3", "--quiet", "--json", str(out), *options]) == 0
    return _without(_json(out), WATCH_TIMING)


@pytest.mark.benchmark
def test_watch_runs_are_pooled_the_same_whatever_ran_them(tmp_path):
    one = _watch(tmp_path, "one")
    assert one == _watch(tmp_path, "two", "--jobs", "2")
    assert one["seeds"] == [0, 1, 2] and one["movements"] == sum(r["movements"] for r in one["per_run"]) == 9
    assert one["segmentation"]["true"] == 9
    # the pool is the runs' counts added: run 1 alone (seed 1) is the second run
    alone = tmp_path / "alone.json"
    assert main(["bench", "watch", "--movements", "3", "--seed", "1", "--quiet", "--json", str(alone)]) == 0
    assert _without(_json(alone)["segmentation"], set()) == one["per_run"][1]["segmentation"]


@pytest.mark.benchmark
def test_watch_on_a_dask_local_cluster(tmp_path):
    _dask()
    assert _watch(tmp_path, "dask", "--scheduler", "local:2") == _watch(tmp_path, "here")


@pytest.mark.benchmark
def test_facilitation_runs_the_same_whatever_ran_them(tmp_path):
    def run(name, *options):
        out = tmp_path / f"{name}.json"
        assert main(["bench", "facilitation", "--demonstrations", "4", "--repertoire", "2", "--runs", "2", "--quiet",
                     "--json", str(out), *options]) == 0
        return _without(_json(out), WATCH_TIMING)

    one = run("one")
    assert one == run("two", "--jobs", "2")
    assert one["demonstrations"] == 8 and [r["run"] for r in one["rows"]] == [0] * 4 + [1] * 4


@pytest.mark.benchmark
def test_vision_one_item_per_resolution(capsys):
    from plugins.bench.vision import vision_benchmark

    pm = create_plugin_manager(autoload=False)
    one = vision_benchmark(pm, "jump_then_cover_face", "max", [60, 120], 6)
    two = vision_benchmark(pm, "jump_then_cover_face", "max", [60, 120], 6, jobs=2)
    strip = [{k: v for k, v in r.items() if k != "ms_per_frame"} for r in one]
    assert strip == [{k: v for k, v in r.items() if k != "ms_per_frame"} for r in two]
    assert [r["perception"] for r in one] == ["synthetic-vision", "rendered-vision 60 px", "rendered-vision 120 px"]


def _memory(capsys, *options: str) -> list[list[str]]:
    """The rows of both tables without their timing and memory columns."""
    assert main(["bench", "memory", "--minutes", "0.05", "--every", "0.05", "--observe-minutes", "0.02",
                 "--observe-minutes", "0.05", *options]) == 0
    rows = []
    for line in capsys.readouterr().out.splitlines():
        cells = line.split()
        if cells and re.fullmatch(r"[\d.]+", cells[0]):
            rows.append(cells[:4] if len(cells) >= 7 and "/usr/bin/time" not in line and "getrusage" not in line
                        else [cells[0], cells[1], cells[4]])  # live: minutes .. rows held; observe: file MB, status
    return rows


@pytest.mark.benchmark
def test_memory_items_the_same_whatever_ran_them(capsys):
    one = _memory(capsys)
    assert one == _memory(capsys, "--jobs", "2")
    assert len(one) == 3 and one[1:] == [["0.02", one[1][1], "0"], ["0.05", one[2][1], "0"]]


def _posegraph(tmp_path: Path, name: str, *options: str) -> list[dict]:
    out = tmp_path / f"{name}.json"
    assert main(["bench", "posegraph", "--nodes", "600", "--nodes", "900", "--queries", "4", "--json", str(out),
                 *options]) == 0
    return [{k: r[k] for k in ("nodes", "parts", "k", "queries", "poses_mb", "agree")} for r in _json(out)]


@pytest.mark.benchmark
def test_posegraph_one_row_per_nodes_whatever_ran_them(tmp_path, capsys):
    one = _posegraph(tmp_path, "one")
    assert one == _posegraph(tmp_path, "two", "--jobs", "2")
    assert [r["nodes"] for r in one] == [600, 900] and all(r["agree"] == "4/4" for r in one)


@pytest.mark.benchmark
def test_posegraph_on_a_dask_local_cluster(tmp_path, capsys):
    _dask()
    assert _posegraph(tmp_path, "dask", "--scheduler", "local:2") == _posegraph(tmp_path, "here")


@pytest.mark.benchmark
def test_scaling_items_the_same_whatever_ran_them(tmp_path, capsys):
    def run(name, *options):
        out = tmp_path / f"{name}.json"
        assert main(["bench", "scaling", "--minutes", "0.05", "--minutes", "0.1", "--movements", "3",
                     "--movements", "4", "--json", str(out), *options]) == 0
        got = _json(out)
        return ([{k: r[k] for k in ("minutes", "frames", "segments")} for r in got["stream"]["rows"]],
                [{k: r[k] for k in ("movements", "clip_frames", "right", "queries", "nodes")}
                 for r in got["repertoire"]["rows"]])

    one = run("one")
    assert one == run("two", "--jobs", "2")
    assert [r["minutes"] for r in one[0]] == [0.05, 0.1] and [r["movements"] for r in one[1]] == [3, 4]


@pytest.mark.benchmark
def test_startup_rounds_in_workers(tmp_path, capsys):
    out = tmp_path / "startup.json"
    assert main(["bench", "startup", "--runs", "2", "--jobs", "2", "--json", str(out)]) == 0
    rows = _json(out)["rows"]
    assert [r["command"] for r in rows] == ["likeme --version", "likeme --help", "likeme plugins",
                                            "likeme plugins --params"]
    assert all(r["runs"] == 2 and 0 < r["min_s"] <= r["median_s"] <= r["max_s"] for r in rows)


@pytest.mark.benchmark
def test_fuzz_cases_the_same_whatever_ran_them():
    from plugins.bench.fuzz import run_fuzz

    pm = create_plugin_manager()

    def run(**where):
        seen = []
        results = run_fuzz(pm, n=8, seed=3, targets=("toml", "scenario"), progress=seen.append, **where)
        assert seen == results
        return [(r.case.index, r.case.target, r.case.mutations, r.case.data, r.outcome) for r in results]

    one = run()
    assert one == run(jobs=2)
    assert [c[0] for c in one] == list(range(8))


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_make_data_writes_the_same_files_whatever_wrote_them(tmp_path):
    from plugins.bench.data import make_data

    pm = create_plugin_manager(autoload=False)
    make_data(pm, tmp_path / "one", seed=4, streams=2, per_stream=2)
    make_data(pm, tmp_path / "two", seed=4, streams=2, per_stream=2, jobs=2)
    one = _files(tmp_path / "one")
    assert one == _files(tmp_path / "two") and "streams/stream_2.bvh" in one


def test_bandai_streams_the_same_whatever_wrote_them(tmp_path):
    from plugins.bench.data import bandai
    from plugins.bench.fuzz import _hand_bvh
    from toolkit.recordings.bvh import parse_bvh
    from toolkit.recordings.bvh_writer import format_bvh

    src = tmp_path / "src"
    src.mkdir()
    for i, content in enumerate(("bow", "bye", "guide")):
        for style in ("normal", "happy", "sad"):  # other styles: the streams' clips
            take = parse_bvh(_hand_bvh())
            take.values[-1] += i  # each clip its own last frame
            # held a third of a second at each end: at rest (plugins.bench.joins.at_rest)
            take.values = np.concatenate([np.repeat(take.values[:1], 10, axis=0), take.values,
                                          np.repeat(take.values[-1:], 10, axis=0)])
            (src / f"dataset-1_{content}_{style}_001.bvh").write_text(format_bvh(take))
    profile = tmp_path / "p.toml"
    profile.write_text("[profile]\n")
    bandai(src, tmp_path / "one", profile, streams=3, per_stream=2)
    bandai(src, tmp_path / "two", profile, streams=3, per_stream=2, jobs=2)
    for folder in ("streams/", "cropped/"):
        one = {k: v for k, v in _files(tmp_path / "one").items() if k.startswith(folder)}
        assert one == {k: v for k, v in _files(tmp_path / "two").items() if k.startswith(folder)}
        assert len(one) == 6
        rows = (tmp_path / "one" / folder / "stream_01.segments.csv").read_text().splitlines()
        assert len(rows) == 3 and rows[1].split(",")[2] in {"bow", "bye", "guide"}


@pytest.mark.parametrize("argv, fragment", [
    (["bench", "watch", "--jobs", "0"], "argument --jobs: invalid value 0"),
    (["bench", "posegraph", "--scheduler", "local:0"], "local:0"),
    (["bench", "watch", "--runs", "2", "--jobs", "2", "--observer", "nobody.toml", "--movements", "1"],
     "nobody.toml"),
])
def test_bad_values_are_one_error_line(argv, fragment, capsys):
    try:
        status = main(argv)
    except SystemExit as exc:
        status = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 1 and len(err) == 1 and err[0].startswith("likeme: error: ") and fragment in err[0]


def test_a_seed_past_the_last_run_is_refused():
    from plugins.bench.watch import watch_runs
    from toolkit.errors import ConfigError
    from toolkit.scenario import MAX_SEED

    with pytest.raises(ConfigError, match="--runs"):
        watch_runs(create_plugin_manager(autoload=False), runs=2, seed=MAX_SEED, movements=1)
