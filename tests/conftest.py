"""Shared fixtures: a plugin manager with the built-ins only, file writers, fixture plugins."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from toolkit import create_plugin_manager, hookimpl, load_scenario
from toolkit.manager import PluginManager

ROOT = Path(__file__).resolve().parent.parent
CHARACTERS = ROOT / "characters"
BANDAI = ROOT.parent / "shared" / "data" / "bandai-namco-1"
"""Real motion capture (CC BY-NC, never copied into the repository); tests that read it skip where it is absent."""

settings.register_profile("likeme", deadline=None)
settings.load_profile("likeme")
"""No test is timed (docs: speed is measured by ``likeme bench``): hypothesis's default deadline (200 ms an example)
is off for every property test, so a loaded CI machine cannot fail one that only ran slowly once
(``tests/test_hypothesis_settings.py``). ``--hypothesis-profile`` still chooses another profile."""

CALLED_HOOKS: set[str] = set()
"""Every hook called, with at least one implementation, through any plugin manager made during the test session."""


@pytest.fixture(autouse=True, scope="session")
def _record_hook_calls():
    """Monitor every plugin manager the tests make (the way tracing does) and note the hooks that ran an implementation:
    ``tests/docs/test_docs.py`` checks that every hook was really called by some test."""
    original = PluginManager.__init__

    def init(self, *args, **kwargs):
        original(self, *args, **kwargs)
        self.add_hookcall_monitoring(lambda name, impls, kwargs: CALLED_HOOKS.add(name) if impls else None,
                                     lambda *_: None)

    PluginManager.__init__ = init
    yield
    PluginManager.__init__ = original


HOOK_CHECK = "test_every_hook_is_called_by_a_test"
"""tests/docs/test_docs.py's check that every hook was called by some test: it needs every other test to have run."""


def pytest_collection_modifyitems(session, config, items):
    """The check that every hook was called runs last, when every other test has run; ``config.whole_suite`` says
    whether every test module was collected (run alone, that check cannot know).

    Under pytest-xdist (``pytest -n auto``) no worker sees every test run: the workers leave that check out and
    send the hooks they saw called to the controller, which makes the check when every worker is done
    (:func:`pytest_sessionfinish`)."""
    last = [i for i in items if i.name.startswith(HOOK_CHECK)]
    items[:] = [i for i in items if i not in last] + last
    collected = {Path(str(i.fspath)).name for i in items}
    config.whole_suite = {p.name for p in (ROOT / "tests").glob("test_*.py")} <= collected
    if hasattr(config, "workerinput") and last:  # an xdist worker
        items[:] = [i for i in items if i not in last]
        config.hook.pytest_deselected(items=last)


_WORKERS: list[tuple[bool, set[str]]] = []
"""(whole suite collected, hooks called) of every xdist worker that finished (on the controller)."""


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """The controller: note what a worker that finished saw."""
    out = getattr(node, "workeroutput", None) or {}
    if "called_hooks" in out:
        _WORKERS.append((out["whole_suite"], set(out["called_hooks"])))


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session, exitstatus):
    """A worker sends the hooks it saw called; the controller checks that every hook was called by some test (on
    any worker), reported as the same tests ``tests/docs/test_docs.py`` defines, when every worker collected every test
    module."""
    config = session.config
    if hasattr(config, "workeroutput"):  # an xdist worker
        config.workeroutput["called_hooks"] = sorted(CALLED_HOOKS)
        config.workeroutput["whole_suite"] = bool(getattr(config, "whole_suite", False))
        return
    if not _WORKERS or not all(whole for whole, _ in _WORKERS):
        return
    from tests.docs.test_docs import HOOKS

    called = set().union(*(hooks for _, hooks in _WORKERS))
    failed = 0
    for name in sorted(HOOKS):
        test = f"{HOOK_CHECK}[{name}]"
        ok = name in called
        failed += not ok
        report = pytest.TestReport(f"tests/docs/test_docs.py::{test}", ("tests/docs/test_docs.py", 0, test), {},
                            "passed" if ok else "failed",
                            None if ok else f"no test made the toolkit call {name} with an implementation registered "
                                            "(on any xdist worker)", "call")
        config.hook.pytest_runtest_logreport(report=report)
    if failed:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def play_recording_postures(path: Path | str, actor: str = "max", **matcher_params):
    """Run a scenario (``matcher_params`` set on the actor's matcher) recording the actor's posture at every frame.

    Returns the world; ``world.postures[i]`` is the actor's local pose at world frame ``i + 1``.
    """

    class Postures:
        def __init__(self) -> None:
            self.frames: list = []

        @hookimpl
        def likeme_world_stepped(self, world):
            self.frames.append(world.actors[actor].local_pose().copy())

    pm = create_plugin_manager(autoload=False)
    postures = Postures()
    pm.register(postures, name="postures")
    scenario = load_scenario(path, pm)
    if matcher_params:
        matcher = scenario.world.actors[actor].character.matcher
        matcher.params = {**matcher.params, **matcher_params}
    world = scenario.run()
    world.postures = np.array(postures.frames)
    return world


STICK_PARTS = ("root", "head", "lk", "rk", "hand", "lf", "rf")
"""The parts of the stick figure whose clips the travel tests write: root, head, knees, a hand and the feet."""


def write_stick_clip(path: Path, positions: np.ndarray, fps: float = 30.0) -> None:
    """A BVH clip of the stick figure: world positions (frames, 7, 3) of :data:`STICK_PARTS`, every part a child of
    the root."""
    from toolkit.bvh import from_joint_positions, write_bvh

    path.parent.mkdir(parents=True, exist_ok=True)
    write_bvh(from_joint_positions(list(STICK_PARTS), [-1] + [0] * (len(STICK_PARTS) - 1), positions, fps), path)


def write_stick_profile(root: Path) -> Path:
    """``root/profile.toml``: the stick figure's body profile (metres, +y up, facing from the knees and the head)."""
    parts = "\n".join(f'{p} = "{p}"' for p in STICK_PARTS)
    path = root / "profile.toml"
    path.write_text(f'[profile]\nname = "stick"\nunits = "metre"\nup = "+y"\n\n[parts]\n{parts}\n\n'
                    '[facing]\nleft = "lk"\nright = "rk"\nforward = "head"\n', encoding="utf-8")
    return path


STICK = """
[character]
name = "Stick"

[body]
parts = ["root", "head", "lk", "rk"]
root = "root"
facing = { left = "lk", right = "rk", forward = "head" }

[motor]
plugin = "keyframe"

[motor.poses.stand]
root = [0.0, 1.0, 0.0]
head = [0.0, 1.6, 0.1]
lk = [0.1, 0.5, 0.0]
rk = [-0.1, 0.5, 0.0]

[motor.poses.bob]
base = "stand"
shift = [0.0, -0.2, 0.0]

[motor.movements.bob]
keys = [{ pose = "stand", at = 0.0 }, { pose = "bob", at = 0.5 }, { pose = "stand", at = 1.0 }]
"""
"""A minimal character: four parts, a keyframe motor with one movement (for tests of the format)."""


@pytest.fixture
def pm():
    """A fresh plugin manager with the built-in plugins only (third-party entry points are not loaded)."""
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture
def max_character(pm):
    """Max the mouse, composed from ``characters/max.toml``."""
    from toolkit import load_character

    return load_character(CHARACTERS / "max.toml", pm)


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
    from tests.fixtures.recorder import Recorder

    plugin = Recorder()
    pm.register(plugin, name="recorder")
    return plugin


@pytest.fixture
def scripted(pm):
    """Register the scripted segmenter and matcher fixture plugin into ``pm``."""
    from tests.fixtures import scripted as module

    pm.register_plugin(module, _info("scripted"))
    return module


def make_plugin(**hooks):
    """A plugin module made of the given functions, each marked as a hook implementation."""
    import types

    from toolkit import hookimpl

    module = types.ModuleType("fixture_plugin")
    for name, func in hooks.items():
        setattr(module, name, hookimpl(func))
    return module


@pytest.fixture
def watch_scene(write):
    """watch_scene(moves, watcher_tables="", watcher=max.toml) -> Path of a scenario file.

    Morris (scripted to perform ``moves`` with 0.5 s pauses) stands 1.6 m in front of the
    watcher, who watches him; ``watcher_tables`` is TOML appended to the watcher's entry
    (``[actors.override.segmenter]`` tables and the like).
    """

    def _scene(moves, watcher_tables: str = "", watcher: Path | str = CHARACTERS / "max.toml") -> Path:
        moves_toml = "[" + ", ".join(f'"{m}"' for m in moves) + "]"
        return write(
            "scene.toml",
            f"""
            [scenario]
            name = "test"
            fps = 30.0

            [[actors]]
            character = "{CHARACTERS / 'morris.toml'}"
            position = [0.0, 0.0, 1.6]
            heading = 180.0
            [actors.override.action]
            plugin = "script"
            movements = {moves_toml}
            random = 0
            pause = 0.5

            [[actors]]
            id = "max"
            character = "{watcher}"
            watch = "morris"
            """
            + textwrap.dedent(watcher_tables),
        )

    return _scene


def _info(name):
    from toolkit.manager import PluginInfo

    return PluginInfo(name, f"tests.fixtures.{name}", "(tests)", "")
