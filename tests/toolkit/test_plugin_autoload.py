"""A third-party plugin that fails to import: a warning naming it and how to disable autoloading; commands go on."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT

BROKEN = ROOT / "tests" / "fixtures" / "likeme-broken"
HINT = "LIKEME_DISABLE_PLUGIN_AUTOLOAD=1"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """pip-install the broken plugin distribution into its own folder (as it would go into site-packages)."""
    target = tmp_path_factory.mktemp("site")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "--no-index", "--quiet",
         "--target", str(target), str(BROKEN)],
        capture_output=True, text=True, cwd=tmp_path_factory.mktemp("build"), timeout=300,
    )
    assert result.returncode == 0, result.stderr
    return target


def _likeme(site, *args, **extra):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    env.pop("LIKEME_DISABLE_PLUGIN_AUTOLOAD", None)
    env.update(extra)
    return subprocess.run([sys.executable, "-m", "toolkit.cli", *map(str, args)], capture_output=True, text=True,
                          env=env, timeout=300)


def test_validate_goes_on_with_one_warning_naming_the_plugin(installed):
    result = _likeme(installed, "validate", ROOT / "characters" / "max.toml")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("ok ")
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("likeme: warning: plugin 'broken' failed in import of likeme_broken")
    for fragment in ("likeme-broken 0.1.0", "entry point broken = likeme_broken", "ModuleNotFoundError", HINT):
        assert fragment in lines[0]
    assert "Traceback" not in result.stderr


def test_plugins_lists_it_as_failed(installed):
    result = _likeme(installed, "plugins")
    assert result.returncode == 0, result.stderr
    assert "broken (likeme_broken, likeme-broken 0.1.0): failed to load, left out" in result.stdout


def test_disabling_autoload_silences_it(installed):
    result = _likeme(installed, "validate", ROOT / "characters" / "max.toml", LIKEME_DISABLE_PLUGIN_AUTOLOAD="1")
    assert result.returncode == 0 and result.stderr == ""


def test_an_unknown_name_mentions_the_plugin_that_failed(installed, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(installed))
    importlib.invalidate_caches()
    from toolkit import ConfigError, create_plugin_manager

    pm = create_plugin_manager(autoload=True)
    assert [info.name for info, _ in pm.failed] == ["broken"]
    assert "broken" not in pm.plugin_infos
    with pytest.raises(ConfigError, match=r"unknown segmenter 'stillnes'.*plugin 'broken' of likeme-broken failed"):
        pm.registry.get("segmenter", "stillnes")
    assert HINT in capsys.readouterr().err


def test_a_builtin_that_fails_to_import_is_an_error(monkeypatch):
    from importlib import metadata

    from toolkit import PluginError
    from toolkit.manager import PluginManager

    real = metadata.entry_points

    def broken_builtin(**kw):
        eps = list(real(**kw))
        ep = next(e for e in eps if e.value.endswith("hub_threshold"))
        bad = metadata.EntryPoint(ep.name, "plugins.no_such_module", ep.group)._for(ep.dist)  # still likeme's own
        return [bad if e is ep else e for e in eps]

    monkeypatch.setattr("toolkit.manager.metadata.entry_points", broken_builtin)
    with pytest.raises(PluginError, match="import of plugins.no_such_module"):
        PluginManager().load_entry_points(third_party=False)
