"""Shared fixtures: a plugin manager with the built-ins only, file writers, fixture plugins."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from toolkit import create_plugin_manager

ROOT = Path(__file__).resolve().parent.parent
CHARACTERS = ROOT / "characters"


@pytest.fixture
def pm():
    """A fresh plugin manager with the built-in plugins only (third-party entry points are not loaded)."""
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture
def write(tmp_path):
    """write(name, text) -> Path: a dedented file in the test's temporary folder."""

    def _write(name: str, text: str) -> Path:
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
        return path

    return _write


@pytest.fixture
def recorder(pm):
    """The event-recording fixture plugin, registered into ``pm``; returns the plugin (its ``calls`` list)."""
    from tests.plugins.recorder import Recorder

    plugin = Recorder()
    pm.register(plugin, name="recorder")
    return plugin


@pytest.fixture
def scripted(pm):
    """Register the scripted segmenter and matcher fixture plugin into ``pm``."""
    from tests.plugins import scripted as module

    pm.register_plugin(module, _info("scripted"))
    return module


def _info(name):
    from toolkit.manager import PluginInfo

    return PluginInfo(name, f"tests.plugins.{name}", "(tests)", "")
