"""The plugin manager: entry points, the component registry, refusals of bad plugins."""

from __future__ import annotations

import pytest

from tests.conftest import make_plugin
from toolkit import ConfigError, MotorSystem, PluginError, Segmenter, create_plugin_manager
from toolkit.manager import PluginInfo

BUILTINS = {"keyframe", "motion-capture", "script", "imitation", "hub-threshold"}


def test_builtins_come_from_the_likeme_entry_points(pm):
    assert BUILTINS <= set(pm.plugin_infos)
    for name in BUILTINS:
        info = pm.plugin_infos[name]
        assert info.distribution == "likeme"
        assert info.module.startswith("plugins.")
    registry = pm.registry
    assert "keyframe" in registry.names("motor")
    assert "motion-capture" in registry.names("perception")
    assert {"script", "imitation"} <= set(registry.names("action"))
    assert registry.info("motor", "keyframe").plugin.name == "keyframe"


def test_unknown_component_lists_registered_names(pm):
    with pytest.raises(ConfigError, match=r"unknown segmenter 'hub-treshold'.*available: hub-threshold"):
        pm.registry.get("segmenter", "hub-treshold")
    with pytest.raises(ConfigError, match=r"unknown action system 'scrip'.*available: hierarchical, imitation, script"):
        pm.registry.get("action", "scrip")




class Still(Segmenter):
    """A segmenter that never segments."""

    name = "still"

    def reset(self, parts, fps):
        pass

    def push(self, pose, visible):
        return []

    def flush(self):
        return []

    @property
    def active_since(self):
        return None


def test_plugin_registered_from_python_is_listed(pm):
    pm.register_plugin(make_plugin(likeme_register_segmenters=lambda: [Still]), PluginInfo("still", "m", "(tests)", ""))
    assert pm.registry.get("segmenter", "still") is Still
    assert pm.registry.info("segmenter", "still").plugin.distribution == "(tests)"


def test_duplicate_component_names_are_refused(pm):
    class Other(Still):
        """Same name."""

    for i, cls in enumerate((Still, Other)):
        pm.register_plugin(make_plugin(likeme_register_segmenters=lambda cls=cls: [cls]), PluginInfo(f"p{i}", "m", "(tests)", ""))
    with pytest.raises(PluginError, match=r"plugin 'p1' failed in likeme_register_segmenters: segmenter name 'still' is already registered by plugin 'p0'"):
        pm.registry


@pytest.mark.parametrize(
    "returned, message",
    [
        (lambda: Still, r"returned <class .*Still.>, expected a list of classes"),
        (lambda: [object], r"expected a subclass of Segmenter"),
        (lambda: [MotorSystem], r"expected a subclass of Segmenter"),
        (lambda: [type("Bad", (Still,), {"name": "Bad Name"})], r"Bad.name is 'Bad Name', expected lower-case words"),
        (lambda: [type("Half", (Segmenter,), {"name": "half"})], r"Half does not implement active_since, flush, push, reset"),
        (lambda: 1 / 0, r"plugin 'bad' failed in likeme_register_segmenters: ZeroDivisionError"),
    ],
)
def test_invalid_registrations_name_the_plugin_and_hook(pm, returned, message):
    pm.register_plugin(make_plugin(likeme_register_segmenters=returned), PluginInfo("bad", "m", "(tests)", ""))
    with pytest.raises(PluginError, match=message):
        pm.registry


def test_unknown_hook_is_refused_at_registration(pm):
    def likeme_register_segmentors():
        return []

    with pytest.raises(PluginError, match=r"plugin 'typo' failed in registration: .*likeme_register_segmentors"):
        pm.register_plugin(make_plugin(likeme_register_segmentors=likeme_register_segmentors), PluginInfo("typo", "m", "(tests)", ""))


def test_disabling_autoload_keeps_the_builtins(monkeypatch):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    pm = create_plugin_manager()
    assert BUILTINS <= set(pm.plugin_infos)
    assert all(i.distribution == "likeme" for i in pm.plugin_infos.values())


def test_tracing_writes_hook_calls(monkeypatch, capsys):
    monkeypatch.setenv("LIKEME_TRACE_HOOKS", "1")
    pm = create_plugin_manager(autoload=False)
    pm.hook.likeme_character_paths()
    assert "likeme_character_paths" in capsys.readouterr().err


def test_character_paths_hook_adds_folders(pm, tmp_path, write):
    folder = tmp_path / "shipped"
    folder.mkdir()
    pm.register_plugin(make_plugin(likeme_character_paths=lambda: [folder]), PluginInfo("ships", "m", "(tests)", ""))
    from toolkit.character import character_paths

    assert folder in character_paths(pm)
