"""``likeme bench sweep`` and ``--jobs`` / ``--scheduler``: the same table whatever ran the cells."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from plugins.bench.data import make_data
from plugins.bench.jobs import run_items
from plugins.bench.sweep import TIMING, cells, load_grid
from toolkit import ConfigError
from toolkit.cli import main
from toolkit.manager import create_plugin_manager

GRID = """benchmark = "segmentation"
[data.gen]
body = "d/profile.toml"
streams = "d/streams"
repertoire = "d/repertoire"
[plugins]
segmenters = ["hub-threshold"]
[set]
"segmenter.min_duration" = [0.25, 0.5, 100.0]
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("sweep")
    make_data(create_plugin_manager(), root / "d", seed=2, streams=2, per_stream=3)
    (root / "grid.toml").write_text(GRID)
    return root


def _table(path: Path) -> list[dict]:
    return [{k: v for k, v in row.items() if k not in TIMING} for row in json.loads(path.read_text())]


def _sweep(folder: Path, name: str, *options: str) -> list[dict]:
    out = folder / f"{name}.json"
    assert main(["bench", "sweep", str(folder / "grid.toml"), "--json", str(out), *options]) == 0
    return _table(out)


def test_run_items_keeps_the_order():
    items = list(range(7, 0, -1))
    assert run_items(abs, items, jobs=3) == items == run_items(abs, items)


def test_the_grid_is_the_product_of_its_lists(folder):
    grid = load_grid(folder / "grid.toml")
    assert [c["values"] for c in cells(grid)] == [{"segmenter.min_duration": v} for v in (0.25, 0.5, 100.0)]
    assert [c["set"] for c in cells(grid)] == [[f"segmenter.min_duration={v}"] for v in ("0.25", "0.5", "100.0")]


def test_sweep_rows_follow_the_settings(folder):
    rows = _sweep(folder, "one")
    assert [r["segmenter.min_duration"] for r in rows] == [0.25, 0.5, 100.0]
    assert {r["plugin"] for r in rows} == {"hub-threshold"} and all(r["items"] == 2 for r in rows)
    # the setting reaches the segmenter: no movement lasts 100 s
    assert rows[0]["recall"] > 0 and rows[2]["recall"] == 0


def test_two_processes_give_the_same_table(folder):
    assert _sweep(folder, "jobs2", "--jobs", "2") == _sweep(folder, "jobs1", "--jobs", "1")


def test_a_dask_local_cluster_gives_the_same_table(folder):
    pytest.importorskip("dask.distributed", reason="dask.distributed not installed: pip install 'likeme[dask]'")
    assert _sweep(folder, "dask", "--scheduler", "local:2") == _sweep(folder, "single")


def test_recognition_with_jobs_prints_the_same_scores(folder, capsys):
    d = folder / "d"
    common = ["bench", "recognition", "--body", str(d / "profile.toml"), "--repertoire", str(d / "repertoire"),
              "--demos", str(d / "demos"), "--matcher", "path-search", "--matcher", "dtw", "--quiet"]
    assert main([*common, "--json", str(folder / "r1.json")]) == 0
    assert main([*common, "--jobs", "2", "--json", str(folder / "r2.json")]) == 0
    one, two = (json.loads((folder / f).read_text()) for f in ("r1.json", "r2.json"))
    strip = [{k: v for k, v in p.items() if k != "fps"} for p in one["plugins"]]
    assert strip == [{k: v for k, v in p.items() if k != "fps"} for p in two["plugins"]]
    assert one["items"] == two["items"]


@pytest.mark.parametrize("text, key", [
    ('benchmark = "segmentation"\nwhat = 1\n', "what"),
    ('benchmark = "posture"\n', "benchmark"),
    (GRID.replace("[plugins]", "[plugins]\nmatcher = []"), "matcher"),
])
def test_unknown_grid_keys_name_the_available(folder, text, key):
    (folder / "bad.toml").write_text(text)
    with pytest.raises(ConfigError) as err:
        load_grid(folder / "bad.toml")
    assert key in str(err.value) and "bad.toml" in str(err.value)
    assert "available" in str(err.value) or "expected" in str(err.value)


def test_a_missing_folder_is_named(folder):
    (folder / "missing.toml").write_text(GRID.replace('"d/streams"', '"d/nowhere"'))
    with pytest.raises(ConfigError, match="nowhere"):
        load_grid(folder / "missing.toml")


def test_a_setting_no_plugin_has_fails_before_any_cell(folder, capsys):
    (folder / "unset.toml").write_text(GRID.replace("segmenter.min_duration", "segmenter.nothing"))
    assert main(["bench", "sweep", str(folder / "unset.toml")]) == 1
    assert "nothing" in capsys.readouterr().err


@pytest.mark.parametrize("where", [{"jobs": 2}, {"scheduler": "local:1"}])
def test_a_workers_error_is_one_error_line_here(folder, where):
    """A bad item's error (here a profile that does not exist) comes back from the worker as a LikemeError."""
    from plugins.bench.mocap import cell
    from toolkit.errors import LikemeError

    if "scheduler" in where:
        pytest.importorskip("dask.distributed", reason="dask.distributed not installed: pip install 'likeme[dask]'")
    spec = {"benchmark": "segmentation", "streams": str(folder / "d" / "streams"), "segmenters": ["hub-threshold"]}
    specs = [{**spec, "body": str(folder / "d" / "profile.toml")}, {**spec, "body": str(folder / "no-profile.toml")}]
    with pytest.raises(LikemeError, match="no-profile.toml"):
        run_items(cell, specs, **where)
