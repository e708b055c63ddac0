"""Start-up: ``likeme --version`` loads nothing, ``--help`` only the plugins that add commands, a command all of them.

Speed itself is measured by ``likeme bench startup`` (figures in docs/benchmarks.md), not by a timed test; these
tests check what is imported, and that a lazy plugin manager ends up the same as an eager one.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT
from toolkit.manager import create_plugin_manager

HEAVY = ("numpy", "scipy", "networkx", "pyvista", "matplotlib", "rich", "dtaidistance", "ruptures", "imageio")


def _modules_after(*args: str, cache: str = "") -> set[str]:
    """The modules imported by ``likeme ARGS`` run in a fresh interpreter (the built-ins only; ``cache``: the
    folder ``likeme plugins`` caches its listing in, none by default)."""
    code = ("import sys, json\nfrom likeme.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            "sys.stderr.write('\\nMODULES ' + json.dumps(sorted(sys.modules)))\n")
    env = {"PYTHONPATH": str(ROOT), "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1", "PATH": "/usr/bin:/bin",
           "LIKEME_CACHE_DIR": cache}
    result = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, timeout=120)
    assert "MODULES " in result.stderr, result.stderr
    return set(json.loads(result.stderr.rsplit("MODULES ", 1)[1]))


def _top(modules: set[str]) -> set[str]:
    return {m.split(".")[0] for m in modules}


def test_version_loads_no_plugin_manager_and_no_library():
    modules = _modules_after("--version")
    assert not {"pluggy", "toolkit.manager", "importlib.metadata", *HEAVY} & (modules | _top(modules))
    assert not any(m.startswith("plugins") for m in modules)


def test_help_imports_only_the_plugins_that_add_commands():
    modules = _modules_after("--help")
    assert "plugins.bench.command" in modules  # declared in the likeme.commands group: bench is in --help
    assert not set(HEAVY) & _top(modules)
    component_modules = {m for m in modules if m.startswith("plugins.") and m.count(".") == 2} - {"plugins.bench.command"}
    assert component_modules == set()


def test_a_command_loads_every_plugin_but_only_the_libraries_their_modules_need():
    modules = _modules_after("plugins", "--params")
    assert {"plugins.segmenters.hub_threshold", "plugins.views.body", "plugins.bench.command", "numpy"} <= modules
    # pyvista and matplotlib (views), dtaidistance (dtw), ruptures, imageio and rich: imported when first used
    assert not {"pyvista", "vtkmodules", "matplotlib", "dtaidistance", "ruptures", "imageio", "rich"} & _top(modules)


def test_the_plugin_listing_is_cached_and_then_imports_no_plugin_and_no_library(tmp_path):
    """``likeme plugins`` lists from the plugins once, then from its cache until anything it depends on changes."""
    first = _modules_after("plugins", cache=str(tmp_path))
    assert "numpy" in first and (tmp_path / "plugins.json").is_file()
    again = _modules_after("plugins", cache=str(tmp_path))
    assert not set(HEAVY) & _top(again)
    assert {m for m in again if m.startswith("plugins.") and m.count(".") == 2} == {"plugins.bench.command"}


def test_the_cached_listing_is_the_listing_and_an_edit_refreshes_it(tmp_path, monkeypatch, capsys):
    from likeme.cli import main
    from likeme.cli.plugins import cache_path

    monkeypatch.setenv("LIKEME_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    assert cache_path() == tmp_path / "plugins.json"
    outputs = []
    for args in (["plugins"], ["plugins"], ["plugins", "--json"], ["plugins", "--json"]):
        assert main(args) == 0
        outputs.append(capsys.readouterr().out)
    assert outputs[0] == outputs[1] and outputs[2] == outputs[3]
    assert "hub-threshold" in outputs[0] and json.loads(outputs[2])["components"]["segmenter"]
    cached = json.loads((tmp_path / "plugins.json").read_text())
    cached["table"]["components"]["segmenter"][0]["summary"] = "STALE"
    (tmp_path / "plugins.json").write_text(json.dumps(cached))
    assert main(["plugins"]) == 0 and "STALE" in capsys.readouterr().out  # served from the cache
    cached["key"] = "another digest"  # what an edit of a plugin's file, an install or an upgrade gives
    (tmp_path / "plugins.json").write_text(json.dumps(cached))
    assert main(["plugins"]) == 0 and capsys.readouterr().out == outputs[0]
    assert json.loads((tmp_path / "plugins.json").read_text())["key"] != "another digest"


def test_the_digest_follows_the_plugins_files(tmp_path, monkeypatch):
    import os

    from toolkit import manager

    pm = create_plugin_manager(autoload=False, trace=False, lazy=True)
    key = pm.entries_fingerprint()
    assert key is not None and key == create_plugin_manager(autoload=False, trace=False, lazy=True).entries_fingerprint()
    source = ROOT / "plugins" / "segmenters" / "hub_threshold.py"
    stat = source.stat()
    real_stat = type(source).stat

    def touched(self, *args, **kwargs):
        result = real_stat(self, *args, **kwargs)
        if self == source:
            return os.stat_result((*result[:8], result.st_mtime + 1, result[9]))
        return result

    monkeypatch.setattr(type(source), "stat", touched)
    assert create_plugin_manager(autoload=False, trace=False, lazy=True).entries_fingerprint() != key
    assert stat.st_size == source.stat().st_size
    assert create_plugin_manager(autoload=False, trace=False, plugins=[("x", manager)]).entries_fingerprint() is None


def _order(pm) -> list[str]:
    return [name for name, _ in pm.list_name_plugin()]


def test_a_lazy_manager_loads_the_same_plugins_in_the_same_order_as_an_eager_one():
    eager = create_plugin_manager(autoload=False, trace=False)
    lazy = create_plugin_manager(autoload=False, trace=False, lazy=True)
    assert _order(lazy) == []
    lazy.load_command_plugins()
    assert _order(lazy) == ["benchmark"]
    lazy.load_all()
    assert _order(lazy) == _order(eager)
    assert len(_order(eager)) > 20
    for hook in ("likeme_register_segmenters", "likeme_register_commands", "likeme_world_stepped"):
        assert ([i.plugin_name for i in getattr(lazy.hook, hook).get_hookimpls()]
                == [i.plugin_name for i in getattr(eager.hook, hook).get_hookimpls()])
    assert lazy.plugin_infos == eager.plugin_infos
    lazy.load_all()  # nothing more to do
    assert _order(lazy) == _order(eager)


def test_a_lazy_managers_registry_has_every_component():
    lazy = create_plugin_manager(autoload=False, trace=False, lazy=True)
    eager = create_plugin_manager(autoload=False, trace=False)
    assert lazy.registry.names("segmenter") == eager.registry.names("segmenter") != []
    assert lazy.registry.names("view") == eager.registry.names("view") != []


def test_plugins_given_in_python_are_registered_after_the_entry_points():
    from tests.conftest import make_plugin

    extra = make_plugin(likeme_world_stepped=lambda world: None)
    lazy = create_plugin_manager(autoload=False, trace=False, lazy=True, plugins=[("extra", extra)])
    assert lazy.get_plugin("extra") is None
    lazy.load_all()
    assert _order(lazy)[-1] == "extra"


def test_the_bench_help_names_the_scripts_limit():
    from plugins.action.script import MAX_RANDOM
    from plugins.bench.command import SCRIPT_MAX_RANDOM

    assert SCRIPT_MAX_RANDOM == MAX_RANDOM


def test_the_toolkit_package_exports_its_names_when_used():
    import toolkit

    for name in toolkit.__all__:
        assert getattr(toolkit, name) is not None
    assert set(toolkit.__all__) <= set(dir(toolkit))
    with pytest.raises(AttributeError, match="no attribute 'Nothing'"):
        toolkit.Nothing  # noqa: B018
    namespace: dict = {}
    exec("from toolkit import *", namespace)
    assert namespace["Motion"] is toolkit.Motion and namespace["create_plugin_manager"] is create_plugin_manager


@pytest.mark.benchmark
def test_bench_startup_times_each_command_in_a_fresh_process(tmp_path, capsys):
    from likeme.cli import main

    out = tmp_path / "startup.json"
    assert main(["bench", "startup", "--runs", "2", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [r["command"] for r in rows] == ["likeme --version", "likeme --help", "likeme plugins", "likeme plugins --params"]
    for r in rows:
        assert r["runs"] == 2 and 0 < r["min_s"] <= r["median_s"] <= r["max_s"]
    text = capsys.readouterr().out
    assert "2 runs each" in text and "likeme plugins" in text.splitlines()[-1]


def test_bench_startup_names_a_command_that_fails():
    from plugins.bench.startup import time_commands
    from toolkit.errors import LikemeError

    failing = [sys.executable, "-c", "import sys; sys.stderr.write('no such thing'); sys.exit(3)"]
    with pytest.raises(LikemeError, match=r"'likeme --version' exited with status 3: no such thing"):
        time_commands(1, failing)


def _fake_distribution(root, commands: str | None) -> None:
    """A third-party distribution ``likeme-fake`` installed into ``root`` (its dist-info, as pip writes it): plugin
    ``fake-a`` adds the command ``fake``, plugin ``fake-b`` a run-event hook; ``commands``: its likeme.commands."""
    info = root / "likeme_fake-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: likeme-fake\nVersion: 1.0\n")
    groups = "[likeme]\nfake-a = likeme_fake_a\nfake-b = likeme_fake_b\n"
    if commands is not None:
        groups += f"\n[likeme.commands]\n{commands} = likeme_fake_a\n"
    (info / "entry_points.txt").write_text(groups)
    (root / "likeme_fake_a.py").write_text(
        "from toolkit import hookimpl\n\n@hookimpl\ndef likeme_register_commands(subparsers):\n"
        "    subparsers.add_parser('fake', help='a third-party command').set_defaults(handler=lambda a, pm: 0)\n")
    (root / "likeme_fake_b.py").write_text("from toolkit import hookimpl\n\n@hookimpl\ndef likeme_world_stepped(world):\n"
                                           "    pass\n")


@pytest.mark.parametrize("commands, early", [(None, ["fake-a", "fake-b"]), ("fake-a", ["fake-a"])])
def test_a_third_party_distribution_declares_its_command_plugins_or_has_all_imported(tmp_path, monkeypatch,
                                                                                      commands, early):
    import importlib

    from likeme.cli import build_parser

    _fake_distribution(tmp_path, commands)
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.invalidate_caches()
    for module in ("likeme_fake_a", "likeme_fake_b"):
        monkeypatch.delitem(sys.modules, module, raising=False)
    lazy = create_plugin_manager(autoload=True, trace=False, lazy=True)
    parser = build_parser(lazy)
    assert [n for n in _order(lazy) if n in ("benchmark", "fake-a", "fake-b")] == ["benchmark", *early]
    assert "hub-threshold" not in _order(lazy)
    assert ("likeme_fake_b" in sys.modules) == ("fake-b" in early)
    assert parser.parse_args(["fake"]).handler(None, lazy) == 0
    lazy.load_all()
    eager = create_plugin_manager(autoload=True, trace=False)
    assert _order(lazy) == _order(eager) and _order(eager).index("fake-b") > _order(eager).index("hub-threshold")
    assert lazy.plugin_infos["fake-b"].distribution == "likeme-fake"
