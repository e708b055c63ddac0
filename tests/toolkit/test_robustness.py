"""Bad frames and odd inputs never crash and never produce evidence that is not there."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS, make_plugin
from toolkit import (
    LikemeError,
    Motion,
    MotorSystem,
    Percept,
    Perception,
    PluginError,
    World,
    create_plugin_manager,
    load_character,
)
from toolkit.manager import PluginInfo


@pytest.fixture(scope="module")
def chars():
    pm = create_plugin_manager(autoload=False)
    return load_character(CHARACTERS / "max.toml", pm), load_character(CHARACTERS / "morris.toml", pm)


def stream(morris, moves, seed):
    rng = np.random.default_rng(seed)
    rest = morris.motor.rest_pose()
    chunks = [np.repeat(rest[None], 20, axis=0)]
    for m in moves:
        chunks += [morris.motor.perform(m, fps=30).positions, np.repeat(rest[None], 15, axis=0)]
    pos = np.concatenate(chunks)
    return pos - pos[:, :1] + rng.normal(0, 0.003, pos.shape)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    moves=st.lists(st.sampled_from(["jump", "wave", "sit", "eat", "kick"]), max_size=3),
    seed=st.integers(0, 10_000),
    hidden=st.floats(0.0, 1.0),
    bad=st.floats(0.0, 0.3),
)
def test_any_occlusion_and_bad_values_keep_the_invariants(chars, moves, seed, hidden, bad):
    max_, morris = chars
    pos = stream(morris, moves, seed)
    rng = np.random.default_rng(seed + 1)
    visible = rng.random(pos.shape[:2]) >= hidden
    corrupt = rng.random(pos.shape) < bad / 3
    pos[corrupt] = rng.choice([np.nan, np.inf, -np.inf], size=int(corrupt.sum()))
    motion = Motion(pos, 30, morris.body.parts, visible)
    assert not motion.visible[~np.isfinite(pos).all(axis=-1)].any()
    segments = max_.segmenter.segment(motion)
    for a, b in zip(segments, segments[1:]):
        assert a.end <= b.start
    for s in segments:
        assert 0 <= s.start < s.end <= motion.n_frames
        match = max_.matcher.match(motion.slice(s.start, s.end))
        assert match.movement is None or match.movement in max_.motor.movements()
        assert 0.0 <= match.confidence <= 1.0
        if not motion.slice(s.start, s.end).visible.any():
            assert match.movement is None  # no recognition without evidence


def test_empty_and_one_frame_motions(chars):
    max_, morris = chars
    parts = morris.body.parts
    empty = Motion(np.zeros((0, len(parts), 3)), 30, parts)
    assert max_.segmenter.segment(empty) == []
    assert not max_.matcher.match(empty).known
    one = Motion(morris.motor.rest_pose()[None] - morris.motor.rest_pose()[0], 30, parts)
    assert max_.segmenter.segment(one) == []
    assert max_.matcher.match(one).movement in (None, *max_.motor.movements())


def test_everything_hidden_for_long_stretches_gives_no_segment(chars):
    max_, morris = chars
    pos = stream(morris, [], 0)
    pos = np.concatenate([pos] * 40)  # 28 s of standing
    visible = np.ones(pos.shape[:2], bool)
    visible[100:600] = False  # all parts hidden for 16 s
    visible[700:800, 5:] = False  # hands, knees and feet hidden for 3 s
    assert max_.segmenter.segment(Motion(pos, 30, morris.body.parts, visible)) == []


def test_a_movement_seen_through_a_long_dropout_is_still_one_segment(chars):
    max_, morris = chars
    pos = stream(morris, ["sit"], 3)
    visible = np.ones(pos.shape[:2], bool)
    visible[40:55] = False  # half a second of nothing in the middle of sitting down
    segments = max_.segmenter.segment(Motion(pos, 30, morris.body.parts, visible))
    assert len(segments) == 1


class Squint(Perception):
    """Returns a pose of the wrong shape (a broken third-party plugin)."""

    name = "squint"

    def perceive(self, observer, target, world):
        return Percept(world.time, np.zeros((2, 3)), np.ones(2, bool), np.zeros((2, 3)), np.zeros(3), 0.0)


class Jitter(Perception):
    """Raises now and then."""

    name = "jitter"

    def perceive(self, observer, target, world):
        raise RuntimeError("sensor fault")


def _world(pm, perception):
    world = World(fps=30, pm=pm, on_plugin_error="stop")
    script = {"action": {"plugin": "script", "movements": ["jump"]}}
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm, override=script), position=(0, 0, 1.6), heading=np.pi)
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm, override={"perception": {"plugin": perception}}))
    max_.watch(morris)
    return world


def test_values_returned_by_a_plugin_are_checked():
    pm = create_plugin_manager(autoload=False)
    pm.register_plugin(make_plugin(likeme_register_perceptions=lambda: [Squint, Jitter]), PluginInfo("bad-eyes", "m", "(tests)", ""))
    world = _world(pm, "squint")
    with pytest.raises(PluginError, match=r"plugin 'squint' failed in Squint.perceive: returned Percept with pose \(2, 3\).*expected a Percept with pose \(11, 3\)"):
        world.step()


def test_a_run_can_go_on_without_a_failing_plugin():
    pm = create_plugin_manager(autoload=False)
    pm.register_plugin(make_plugin(likeme_register_perceptions=lambda: [Squint, Jitter]), PluginInfo("bad-eyes", "m", "(tests)", ""))
    world = _world(pm, "jitter")
    with pytest.raises(PluginError, match="plugin 'jitter' failed in Jitter.perceive: RuntimeError: sensor fault"):
        world.step()
    world = _world(pm, "jitter")
    world.on_plugin_error = "skip"
    world.run(3.0)
    failed = [e for e in world.events if e.kind == "plugin_failed"]
    assert len(failed) == 1 and failed[0].data["plugin"] == "jitter" and failed[0].actor == "max"
    assert world.actors["max"].character.perception is None
    assert world.actors["morris"].performed  # the rest of the world went on


def test_a_failing_hook_implementation_is_named_or_dropped():
    pm = create_plugin_manager(autoload=False)

    class Crashy:
        def likeme_world_stepped(self, world):
            raise ValueError("boom")

    from toolkit import hookimpl

    Crashy.likeme_world_stepped = hookimpl(Crashy.likeme_world_stepped)
    pm.register_plugin(Crashy(), PluginInfo("crashy", "m", "(tests)", ""))
    world = _world(pm, "synthetic-vision")
    with pytest.raises(PluginError, match="plugin 'crashy' failed in likeme_world_stepped: ValueError: boom"):
        world.step()
    world.on_plugin_error = "skip"
    world.step()
    assert not pm.has_plugin("crashy")
    assert [e.data["where"] for e in world.events if e.kind == "plugin_failed"] == ["likeme_world_stepped"]


class Empty(MotorSystem):
    """A motor system whose movements are empty (broken)."""

    name = "empty"

    def movements(self):
        return ["nothing"]

    def rest_pose(self):
        return np.zeros((len(self.owner.body.parts), 3))

    def perform(self, movement, *, speed=1.0, fps=30.0):
        return Motion(np.zeros((0, len(self.owner.body.parts), 3)), fps, self.owner.body.parts)


def test_an_empty_motion_from_a_motor_system_is_refused(write):
    from toolkit import MovementRequest

    pm = create_plugin_manager(autoload=False)
    pm.register_plugin(make_plugin(likeme_register_motor_systems=lambda: [Empty]), PluginInfo("empty", "m", "(tests)", ""))
    path = write("e.toml", '[character]\nname = "E"\n[body]\nparts = ["r", "a", "b"]\nroot = "r"\nfacing = { left = "a", right = "b" }\n[motor]\nplugin = "empty"\n')
    world = World(fps=30, pm=pm)
    actor = world.add_actor(load_character(path, pm))
    with pytest.raises(PluginError, match=r"plugin 'empty' failed in Empty.perform: returned Motion\(0 frames"):
        actor.request(MovementRequest("nothing"))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=st.text(max_size=300))
def test_fuzzed_toml_raises_only_documented_errors(tmp_path, text):
    pm = create_plugin_manager(autoload=False)
    path = tmp_path / "fuzz.toml"
    path.write_text(text, encoding="utf-8")
    try:
        load_character(path, pm)
    except LikemeError:
        pass


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_character_files_raise_only_documented_errors(tmp_path, data):
    """Take Max's file, drop or rewrite some lines: any result loads or fails with a LikemeError."""
    pm = create_plugin_manager(autoload=False)
    lines = (CHARACTERS / "max.toml").read_text().splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        action = data.draw(st.sampled_from(["drop", "value", "key"]))
        if action == "drop":
            lines.pop(i)
        elif "=" in lines[i]:
            key, _, _ = lines[i].partition("=")
            value = data.draw(st.sampled_from(['"x"', "1", "-3.5", "true", "[]", "{}", '["a", 2]', "[0.0, 1.0]", "nan"]))
            lines[i] = f"{key}= {value}" if action == "value" else f"{data.draw(st.sampled_from(['zzz', 'plugin', 'base', 'keys']))} = {value}"
    path = tmp_path / "mutant.toml"
    path.write_text("\n".join(lines), encoding="utf-8")
    try:
        load_character(path, pm)
    except LikemeError:
        pass


@settings(max_examples=40, deadline=None)
@given(
    objects=st.lists(
        st.tuples(st.sampled_from(["cheese", "ball", "baton", "ice_cream", "rock"]),
                  st.floats(-1.5, 1.5), st.floats(0.0, 1.5), st.floats(-1.5, 1.5)),
        max_size=5),
    hunger=st.floats(0, 1), play=st.floats(0, 1),
)
def test_action_selection_always_gives_a_possible_path_or_nothing(objects, hunger, play):
    from toolkit import TriggerContext, WorldObject

    pm = create_plugin_manager(autoload=False)
    world = World(fps=30, pm=pm)
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm))
    for i, (kind, x, y, z) in enumerate(objects):
        world.add_object(WorldObject(f"{kind}-{i}", kind, (x, y, z)))
    system = morris.character.action
    system.drives["hunger"].level, system.drives["play"].level = hunger, play
    decision = system.decide(morris, world)
    if decision is None:
        return
    path, obj = decision
    assert path in system.hierarchy.paths_to(path[-1]) and system.hierarchy.tuples[path[-1]].leaf
    context = TriggerContext(morris, world, obj, system.beliefs, {n: d.level for n, d in system.drives.items()})
    for name in path:
        assert all(t.evaluate(context) > 0 for t in system.hierarchy.tuples[name].can)
    assert obj in world.objects and system.beliefs.get(world.objects[obj].kind) is not None


# -- fuzzed motion-capture input: BVH files and body profiles fail only with a ConfigError

def _small_bvh_text() -> str:
    from toolkit.recordings.bvh_writer import format_bvh, from_joint_positions
    rng = np.random.default_rng(0)
    positions = np.cumsum(rng.normal(0, 1, (3, 4, 3)), axis=0) + np.array([[0, 90, 0], [0, 100, 0], [5, 100, 0], [0, 80, 5]])
    return format_bvh(from_joint_positions(["hips", "chest", "arm", "leg"], [-1, 0, 1, 0], positions, 30.0))


BVH_TEXT = _small_bvh_text()
BVH_TOKENS = ["{", "}", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "0", "3", "6", "7", "-1", "1e999", "nan",
              "inf", "Xrotation", "Wrotation", "Frames:", "Frame", "Time:", "0.0", "-0.5", "MOTION", "HIERARCHY", "hips",
              "", "\t", "\r\n"]


def _read_all(text: str, profile=None):
    from toolkit.recordings.bvh import parse_bvh
    bvh = parse_bvh(text, "fuzz.bvh")
    positions = bvh.positions()
    assert positions.shape == (bvh.n_frames, len(bvh.names), 3)
    if profile is not None:
        profile.motion(bvh)


@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_mutated_bvh_files_raise_only_config_errors(data):
    """Drop, replace, insert or truncate tokens of a valid file: it reads or fails with a ConfigError, nothing else."""
    from toolkit import ConfigError

    tokens = BVH_TEXT.replace("\n", " \n ").split(" ")
    for _ in range(data.draw(st.integers(1, 5))):
        i = data.draw(st.integers(0, len(tokens) - 1))
        action = data.draw(st.sampled_from(["drop", "replace", "insert", "truncate"]))
        if action == "drop":
            tokens.pop(i)
        elif action == "replace":
            tokens[i] = data.draw(st.sampled_from(BVH_TOKENS))
        elif action == "insert":
            tokens.insert(i, data.draw(st.sampled_from(BVH_TOKENS)))
        else:
            tokens = tokens[:i]
        if not tokens:
            tokens = [""]
    try:
        _read_all(" ".join(tokens))
    except ConfigError as err:
        assert "fuzz.bvh" in str(err)


@settings(max_examples=80, deadline=None)
@given(text=st.text(max_size=200))
def test_arbitrary_text_as_bvh_raises_only_config_errors(text):
    from toolkit import ConfigError

    try:
        _read_all(text)
    except ConfigError as err:
        assert "fuzz.bvh" in str(err)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_profiles_raise_only_config_errors(tmp_path, data):
    """Take the Bandai-Namco profile, drop or rewrite lines: it loads (and reads a file) or fails with a ConfigError."""
    from toolkit import ConfigError
    from toolkit.recordings.profile import load_profile

    lines = (CHARACTERS / "profiles" / "bandai-namco.toml").read_text().splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        action = data.draw(st.sampled_from(["drop", "value", "key", "table"]))
        if action == "drop":
            lines.pop(i)
        elif action == "table":
            lines.insert(i, data.draw(st.sampled_from(["[facing]", "[parts]", "[profile]", "[bones]", "[extra]", "[[parts]]"])))
        elif "=" in lines[i]:
            key, _, _ = lines[i].partition("=")
            value = data.draw(st.sampled_from(['"x"', '"Hips"', "1", "-3.5", "0", "true", "[]", "{}", '["a", "b"]', "nan",
                                               '"+q"', '"furlong"', '"root"']))
            lines[i] = f"{key}= {value}" if action == "value" else \
                f"{data.draw(st.sampled_from(['zzz', 'root', 'left', 'units', 'up', 'forward']))} = {value}"
    path = tmp_path / "mutant.toml"
    path.write_text("\n".join(lines), encoding="utf-8")
    try:
        profile = load_profile(path)
    except ConfigError as err:
        assert "mutant.toml" in str(err)
        return
    from toolkit.recordings.bvh_writer import format_bvh, from_joint_positions
    rng = np.random.default_rng(1)
    names = list(dict.fromkeys(profile.joints))
    text = format_bvh(from_joint_positions(names, [-1] + [0] * (len(names) - 1), rng.normal(0, 50, (2, len(names), 3)), 30.0))
    try:
        _read_all(text, profile)
    except ConfigError:
        pass


# -- issue 38: numbers no body has, and messages a terminal shows --------------------------------------------------


def test_coordinates_no_body_has_are_not_seen_and_warn_nothing(tmp_path):
    """A joint coordinate of 1e308 (any beyond ``MAX_COORDINATE``) is read as not seen in its frame: the observer
    goes on with no RuntimeWarning (each numpy overflow is turned into an error here: one would fail the run)."""
    import contextlib
    import io
    import warnings

    from likeme.cli import main
    from tests.conftest import STICK_PARTS, write_stick_clip, write_stick_profile
    from toolkit.recordings.recording import MAX_COORDINATE

    profile = write_stick_profile(tmp_path)
    stand = np.array([[0, 1, 0], [0, 1.6, 0.1], [0.1, 0.5, 0], [-0.1, 0.5, 0], [0.3, 1.0, 0], [0.1, 0, 0],
                      [-0.1, 0, 0]], float)
    t = np.linspace(0, 1, 31)
    bob = stand[None] + np.sin(np.pi * t)[:, None, None] * np.array([0.0, -0.2, 0.0])
    write_stick_clip(tmp_path / "rep" / "bob" / "a.bvh", bob)
    stream = np.concatenate([np.repeat(stand[None], 20, 0), bob, np.repeat(stand[None], 20, 0)])
    stream[25, 1] = [1e308, -1e308, 1e308]
    stream[26, 4] = [2 * MAX_COORDINATE, 0.0, 0.0]
    path = tmp_path / "s.npy"
    np.save(path, stream)
    from toolkit.recordings.positions import read_positions

    got = read_positions(path, names=list(STICK_PARTS), fps=30.0)
    assert np.isnan(got.positions[25, 1]).all() and np.isnan(got.positions[26, 4]).all()
    assert np.isfinite(np.delete(got.positions, [25, 26], axis=0)).all()
    (tmp_path / "profile.toml").write_text(profile.read_text().replace("[parts]", f"fps = 30.0\njoints = "
                                           f"{list(STICK_PARTS)!r}\n\n[parts]".replace("'", '"'), 1))
    err = io.StringIO()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            status = main(["observe", "--body", str(profile), "--repertoire", str(tmp_path / "rep"), str(path)])
    assert status == 0 and "Warning" not in err.getvalue(), err.getvalue()


@given(st.text(max_size=3000), st.integers(1, 2000))
def test_a_message_part_is_printable_and_bounded(text, limit):
    from toolkit.errors import printable

    out = printable(text, limit)
    assert out.isprintable() and "\n" not in out
    kept = out.split("... (")[0] if len(text) > limit else out
    assert len(kept) <= 10 * limit  # each character kept or escaped (at most \U0010ffff: 10 characters)
    if len(text) > limit:
        assert out.endswith(f"... ({len(text) - limit:,} more characters)")
    if text.isprintable() and len(text) <= limit:
        assert out == text


def test_a_list_of_names_ends_with_how_many_more():
    from toolkit.errors import ConfigError

    err = ConfigError("unknown", available=[f"n{i}" for i in range(1_000_000)])
    assert str(err).endswith("n59 and 999,940 more") and len(str(err)) < 1000
