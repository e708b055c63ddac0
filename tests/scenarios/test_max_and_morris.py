"""Buchsbaum & Blumberg 2005, §5: Max parses, recognises and imitates Morris (scenario tests of the paper's examples)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS
from toolkit import Motion, World, create_plugin_manager, load_character, load_scenario


@pytest.fixture(scope="module")
def chars():
    pm = create_plugin_manager(autoload=False)
    return load_character(CHARACTERS / "max.toml", pm), load_character(CHARACTERS / "morris.toml", pm)


def observed(character, movement, *, noise=0.0, seed=0):
    """Morris's movement as Max would see it with perfect tracking: root-relative, plus optional noise."""
    m = character.motor.perform(movement, fps=30).root_relative("root")
    if noise:
        m = Motion(m.positions + np.random.default_rng(seed).normal(0, noise, m.positions.shape), m.fps, m.parts)
    return m


def test_fig4_jump_then_cover_face_two_segments_recognised_and_imitated():
    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario(CHARACTERS / "scenarios" / "jump_then_cover_face.toml", pm)
    world = scenario.run()
    segments = [e.data["segment"] for e in world.events_of("segment_found", "max")]
    assert len(segments) == 2
    recognised = [e.data["match"].movement for e in world.events_of("movement_recognised", "max")]
    assert recognised == ["jump", "cover_face"]
    # each segment lies over the movement Morris performed
    morris = world.actors["morris"]
    max_ = world.actors["max"]
    for seg, (frame, request) in zip(segments, morris.performed):
        n = morris.character.motor.perform(request.movement, fps=world.fps).n_frames
        start, end = max_.watch_start + seg.start, max_.watch_start + seg.end
        assert frame <= start < end <= frame + n + 2
    # the nose was hidden behind Morris's hands for part of the cover face
    nose = max_.memory.visible[:, morris.body.index("nose")]
    assert not nose.all()
    # §5.3: Max imitates by performing his own movements
    assert [(r.movement, r.imitating) for _, r in max_.performed] == [("jump", "morris"), ("cover_face", "morris")]


def test_morris_longer_head_shaking_cover_face_is_max_cover_face(chars):
    max_, morris = chars
    assert morris.motor.perform("cover_face").duration > 1.5 * max_.motor.perform("cover_face").duration
    match = max_.matcher.match(observed(morris, "cover_face", noise=0.004))
    assert match.movement == "cover_face"
    assert match.details["mean_distance"] > 0.001  # not identical to his own, but closest


def test_jump_with_its_first_third_unseen_is_still_a_jump(chars):
    max_, morris = chars
    jump = observed(morris, "jump", noise=0.003)
    third = jump.n_frames // 3
    assert max_.matcher.match(jump.slice(third)).movement == "jump"  # beginning missed
    hidden = np.ones(jump.visible.shape, bool)
    hidden[:third] = False
    assert max_.matcher.match(jump.with_visibility(hidden)).movement == "jump"  # beginning not visible


def test_extra_standing_frames_before_and_after_do_not_matter(chars):
    max_, morris = chars
    rest = np.repeat(morris.motor.rest_pose()[None], 20, axis=0)
    rest = rest - rest[:, :1]
    for movement in ("wave", "kick", "eat"):
        m = observed(morris, movement)
        padded = Motion(np.concatenate([rest, m.positions, rest]), 30, m.parts)
        assert max_.matcher.match(padded).movement == movement


def test_cover_face_with_hands_and_nose_hidden_part_of_the_time(chars):
    max_, morris = chars
    m = observed(morris, "cover_face", noise=0.003)
    visible = m.visible.copy()
    for part in ("nose", "left_hand", "right_hand"):
        i = m.parts.index(part)
        visible[m.n_frames // 4 : 3 * m.n_frames // 4 : 2, i] = False  # every other frame in the middle half
        visible[m.n_frames // 3 : m.n_frames // 2, i] = False
    assert max_.matcher.match(m.with_visibility(visible)).movement == "cover_face"


@pytest.mark.parametrize("group", [("wave", "knock", "thumbs_up"), ("reach_high", "jump"), ("wave", "wave_left", "wave_both")])
def test_similar_movements_are_told_apart(chars, group):
    max_, morris = chars
    for seed in range(3):
        for movement in group:
            assert max_.matcher.match(observed(morris, movement, noise=0.005, seed=seed)).movement == movement


def test_unknown_movement_is_unknown_then_learned(chars, write):
    pm = create_plugin_manager(autoload=False)
    teacher = write(
        "teacher.toml",
        f"""
        [character]
        name = "Teacher"
        extends = "{CHARACTERS / 'morris.toml'}"

        [motor.poses.windmill_a]
        base = "stand"
        left_hand = [0.30, 0.45, 0.0]
        right_hand = [-0.05, 0.10, 0.15]
        left_elbow = [0.18, 0.42, 0.0]

        [motor.poses.windmill_b]
        base = "stand"
        right_hand = [-0.30, 0.45, 0.0]
        left_hand = [0.05, 0.10, 0.15]
        right_elbow = [-0.18, 0.42, 0.0]

        [motor.movements.windmill]
        keys = [{{ pose = "stand", at = 0.0 }}, {{ pose = "windmill_a", at = 0.5 }}, {{ pose = "windmill_b", at = 1.0 }},
                {{ pose = "windmill_a", at = 1.5 }}, {{ pose = "stand", at = 2.0 }}]
        """,
    )
    learner = write(
        "learner.toml",
        f"""
        [character]
        name = "Learner"
        extends = "{CHARACTERS / 'max.toml'}"
        [matcher]
        learn = true
        """,
    )
    t = load_character(teacher, pm)
    max_ = chars[0]
    assert not max_.matcher.match(observed(t, "windmill")).known
    learner = load_character(learner, pm)
    first = learner.matcher.match(observed(t, "windmill"))
    assert first.movement == "learned-1" and first.details["learned"]
    assert "learned-1" in learner.motor.movements()
    again = learner.matcher.match(observed(t, "windmill", noise=0.003, seed=5))
    assert again.movement == "learned-1" and not again.details.get("learned")
    assert learner.matcher.match(observed(t, "jump")).movement == "jump"
    # the learned movement can be performed (imitated) through the motor system
    motion = learner.motor.perform("learned-1", fps=30)
    assert motion.n_frames > 30


def test_standing_still_for_a_long_time_gives_no_segment(chars):
    max_, morris = chars
    rest = morris.motor.rest_pose()
    frames = np.repeat(rest[None], 30 * 120, axis=0)
    frames = frames - frames[:, :1] + np.random.default_rng(1).normal(0, 0.004, frames.shape)
    assert max_.segmenter.segment(Motion(frames, 30, morris.body.parts)) == []


def _stream(morris, moves, noise, seed):
    rng = np.random.default_rng(seed)
    rest = morris.motor.rest_pose()
    chunks, truth, t = [np.repeat(rest[None], 15, axis=0)], [], 15
    for m in moves:
        motion = morris.motor.perform(m, fps=30).positions
        chunks.append(motion)
        truth.append((t, t + len(motion)))
        t += len(motion)
        chunks.append(np.repeat(rest[None], 15, axis=0))
        t += 15
    pos = np.concatenate(chunks)
    pos = pos - pos[:, :1] + rng.normal(0, noise, pos.shape)
    return Motion(pos, 30, morris.body.parts), truth


@settings(max_examples=15, deadline=None)
@given(
    moves=st.lists(st.sampled_from(["jump", "wave", "reach", "sit", "clap", "kick", "bow"]), min_size=1, max_size=5),
    noise=st.floats(0.0, 0.004),
    seed=st.integers(0, 1000),
    drop=st.floats(0.0, 0.3),
)
def test_segments_are_ordered_disjoint_and_streaming_equals_batch(chars, moves, noise, seed, drop):
    max_, morris = chars
    motion, truth = _stream(morris, moves, noise, seed)
    mask = np.random.default_rng(seed).random(motion.visible.shape) >= drop
    motion = motion.with_visibility(mask)
    batch = max_.segmenter.segment(motion)
    streaming = []
    max_.segmenter.reset(motion.parts, motion.fps)
    for f in range(motion.n_frames):
        streaming.extend(max_.segmenter.push(motion.positions[f], motion.visible[f]))
    streaming.extend(max_.segmenter.flush())
    assert batch == streaming
    for a, b in zip(batch, batch[1:]):
        assert a.end <= b.start
    assert len(batch) == len(truth)
    for seg in batch:
        match = max_.matcher.match(motion.slice(seg.start, seg.end))
        assert match.movement is None or match.movement in max_.motor.movements()


def test_a_target_that_is_never_visible_gives_no_segment_and_no_recognition(chars):
    pm = create_plugin_manager(autoload=False)
    world = World(fps=30)
    script = {"action": {"plugin": "script", "movements": ["jump", "wave", "sit"]}}
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm, override=script), position=(0, 0, -2.0))  # behind Max
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm))
    max_.watch(morris)
    world.run(12.0)
    assert morris.performed  # he did move
    assert not max_.memory.visible.any()
    assert world.events_of("segment_found") == [] and world.events_of("movement_recognised") == []


def test_a_world_actors_working_memory_is_bounded_and_its_answers_do_not_depend_on_it(monkeypatch):
    """A world may run for hours: an actor's working memory keeps the world's ``memory_seconds`` beyond the segment
    under way (:class:`toolkit.watching.WatchingLoop`'s ``keep``), not every frame since it began watching."""
    from toolkit.watching import ObservationLog

    monkeypatch.setattr(ObservationLog, "slack", 16)  # let rows go after 16 unused, not 1024: a short scenario
    pm = create_plugin_manager(autoload=False)
    runs = []
    for seconds in (None, 0.5):
        scenario = load_scenario(CHARACTERS / "scenarios" / "jump_then_cover_face.toml", pm)
        world = scenario.world
        world.memory_seconds = seconds
        world.actors["max"].watch(world.actors["morris"])  # watching begun again, at frame 0, with this history
        world = scenario.run()
        max_ = world.actors["max"]
        runs.append(([(e.data["segment"].start, e.data["segment"].end) for e in world.events_of("segment_found", "max")],
                     [e.data["match"].movement for e in world.events_of("movement_recognised", "max")],
                     [(r.movement, r.imitating) for _, r in max_.performed], max_.memory.offset, max_.memory.n))
    (segments, recognised, performed, offset, n), short = runs
    assert short[:3] == (segments, recognised, performed) and recognised == ["jump", "cover_face"]
    assert offset == 0 and short[3] > 0 and short[4] == n  # rows forgotten, every frame still counted
    assert short[4] - short[3] <= max(2 * (30 // 2 + 1), 16)  # after the last segment: about twice the 0.5 s kept
