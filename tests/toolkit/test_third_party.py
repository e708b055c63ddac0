"""Third-party extension for real: the likeme-stillness distribution, installed with pip, selected by name in TOML."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys

import pytest

from tests.conftest import CHARACTERS, ROOT

EXAMPLE = ROOT / "tests" / "fixtures" / "likeme-stillness"


@pytest.fixture(scope="session")
def installed(tmp_path_factory):
    """pip-install the example plugin distribution into its own folder (as it would go into site-packages)."""
    target = tmp_path_factory.mktemp("site")
    build = tmp_path_factory.mktemp("build")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "--no-index", "--quiet",
         "--target", str(target), str(EXAMPLE)],
        capture_output=True, text=True, cwd=build, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    assert list(target.glob("likeme_stillness-1.0.0.dist-info/entry_points.txt"))
    return target


def _env(site, **extra):
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)]), **extra}


def _likeme(site, *args, **extra):
    return subprocess.run(
        [sys.executable, "-m", "toolkit.cli", *map(str, args)], capture_output=True, text=True, env=_env(site, **extra), timeout=300
    )


CHARACTER = f"""
[character]
name = "Still Max"
extends = "{CHARACTERS / 'max.toml'}"

[segmenter]
plugin = "stillness"
hold = 0.3

[perception]   # the exact geometric eye: this segmenter thresholds the raw speed between two frames, which a
               # camera's pixels exceed once Max moves his head (imitating) and everything he sees shifts a little
plugin = "synthetic-vision"
eye = "head"
radii = {{ head = 0.06, left_hand = 0.045, right_hand = 0.045 }}
"""


def test_installed_plugin_is_listed_with_its_distribution(installed):
    result = _likeme(installed, "plugins")
    assert result.returncode == 0, result.stderr
    line = next(l for l in result.stdout.splitlines() if l.strip().startswith("stillness"))
    assert "[likeme-stillness 1.0.0: stillness]" in line


def test_toml_character_selects_the_third_party_segmenter(installed, write):
    path = write("still_max.toml", CHARACTER)
    ok = _likeme(installed, "validate", path)
    assert ok.returncode == 0, ok.stderr
    assert "segmenter stillness" in ok.stdout
    # without autoloading, the same file names what is registered instead
    off = _likeme(installed, "validate", path, LIKEME_DISABLE_PLUGIN_AUTOLOAD="1")
    assert off.returncode == 1 and "unknown segmenter 'stillness'" in off.stderr


def test_run_with_the_third_party_segmenter(installed, write, watch_scene):
    scene = watch_scene(["jump", "wave", "jump"], watcher=write("still_max.toml", CHARACTER))
    result = _likeme(installed, "run", scene, "--json")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    max_ = next(a for a in data["actors"] if a["id"] == "max")
    morris = next(a for a in data["actors"] if a["id"] == "morris")
    segments = max_["watching"]["segments"]
    assert len(segments) == 3
    for seg, did in zip(segments, morris["did"]):
        assert abs(seg["start_frame"] - did["frame"]) <= 3


def test_loaded_in_process_through_the_same_loader(installed, monkeypatch):
    monkeypatch.syspath_prepend(str(installed))
    importlib.invalidate_caches()
    from toolkit import create_plugin_manager

    pm = create_plugin_manager(autoload=True)
    info = pm.registry.info("segmenter", "stillness")
    assert info.plugin.distribution == "likeme-stillness" and info.plugin.version == "1.0.0"
    assert pm.plugin_infos["stillness"].module == "likeme_stillness"
