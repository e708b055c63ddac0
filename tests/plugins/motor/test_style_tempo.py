"""The posegraph's ``tempo`` (issue 18): each clip sampled at its own tempo, and path search sampling a demonstration
the same way.

A movement's frequency is its RMS speed over its RMS distance from its mean posture (plugins.lib.style); a clip is
sampled at ``node_rate`` times its frequency over the repertoire's median clip frequency, within ``tempo`` times
either way. On Morris's generated takes (speeds 0.8, 1.0 and 1.25 of each movement) the same movement then gets
about as many nodes at every speed, and a demonstration performed much slower than one's own is followed.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.toolkit.test_relative_lengths import generated  # noqa: F401  (the generated recordings, a module fixture)
from toolkit import Motion, create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.profile import load_profile

MOVEMENTS = ("wave", "reach", "clap", "bow", "knock")


def repertoire(folder, generated, speed: str):
    """A repertoire folder of links to Morris's takes at ``speed`` of each of :data:`MOVEMENTS`."""
    for movement in MOVEMENTS:
        (folder / movement).mkdir(parents=True)
        clip = generated / "demos" / movement / f"morris_{speed}.bvh"
        (folder / movement / clip.name).symlink_to(clip)
    return folder


@pytest.fixture(scope="module")
def fast(generated, tmp_path_factory):
    return repertoire(tmp_path_factory.mktemp("fast"), generated, "1.25")


@pytest.fixture(scope="module")
def slow(generated, tmp_path_factory):
    return repertoire(tmp_path_factory.mktemp("slow"), generated, "0.8")


def observer(generated, folder, *, motor=None, matcher=None):
    pm = create_plugin_manager(autoload=False, trace=False)
    return compose_observer(pm, load_profile(generated / "profile.toml"), folder,
                            settings={"motor": motor or {}, "matcher": matcher or {}})


def slowed(motion: Motion, factor: float) -> Motion:
    """``motion`` performed ``factor`` times as slowly (each coordinate interpolated in time; at the same frame
    rate)."""
    n = int(round((motion.n_frames - 1) * factor)) + 1
    t = np.linspace(0.0, motion.n_frames - 1, n)
    flat = motion.positions.reshape(motion.n_frames, -1)
    positions = np.stack([np.interp(t, np.arange(motion.n_frames), c) for c in flat.T], axis=1)
    return Motion(positions.reshape(n, *motion.positions.shape[1:]), motion.fps, motion.parts)


def test_without_tempo_every_clip_is_sampled_at_the_node_rate(generated, fast):
    motor = observer(generated, fast).motor
    assert motor.reference_frequency == 0.0 and motor.tempo_factor(3.0) == 1.0
    for movement, (take,) in motor.takes().items():
        clip = next(c.motion for c in motor.clips.clips if c.movement == movement)
        assert abs(len(take) + 2 - clip.duration * motor.node_rate) <= 1.5  # the ends are hubs


def test_the_tempo_factor_is_the_frequency_over_the_median_within_the_limit(generated, fast):
    motor = observer(generated, fast, motor={"tempo": 2.0}).motor
    ref = motor.reference_frequency
    found = [motor.frequency(*motor._sampled(c.motion)) for c in motor.clips.clips]
    assert ref == pytest.approx(np.median(found)) and ref > 0
    assert motor.tempo_factor(ref * 1.5) == pytest.approx(1.5)
    assert motor.tempo_factor(ref / 1.5) == pytest.approx(1 / 1.5)
    assert motor.tempo_factor(ref * 5) == pytest.approx(2.0) and motor.tempo_factor(ref / 5) == pytest.approx(0.5)
    assert motor.tempo_factor(0.0) == 1.0


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scale=st.floats(0.5, 2.0), offset=st.tuples(*[st.floats(-0.3, 0.3)] * 3), part=st.integers(1, 10))
def test_the_frequency_does_not_change_with_the_size_or_a_held_offset_of_a_part(generated, fast, scale, offset,
                                                                                part):
    motor = observer(generated, fast).motor
    clip = motor.clips.clips[0].motion
    keep, filled = motor._sampled(clip)
    root = motor.body.root_index
    rel = filled - filled[:, root:root + 1]
    moved = rel * scale
    moved[:, part] += offset
    assert motor.frequency(keep, moved) == pytest.approx(motor.frequency(keep, rel), rel=1e-9)


def test_the_frequency_of_a_sinusoid_is_its_angular_frequency():
    """x = A sin(w t) of one part about the root: RMS speed A w / 2**0.5 over RMS distance A / 2**0.5 is w; the steps
    between samples 10 a second read 20 sin(w / 20) (over many periods, so the ends count little)."""
    from plugins.lib.style import frequency

    t = np.arange(0, 60.0, 0.1)
    for w in (2.0, 5.0):
        poses = np.zeros((len(t), 2, 3))
        poses[:, 1, 0] = 0.3 * np.sin(w * t)
        f = frequency(poses, np.ones(poses.shape[:2], bool), 10.0)
        assert f == pytest.approx(20 * np.sin(w / 20), rel=0.005) and f == pytest.approx(w, rel=0.011)


def test_with_tempo_a_movement_gets_about_as_many_nodes_at_every_speed(generated, tmp_path):
    """A repertoire of two takes of each movement, at speeds 0.8 and 1.25: without tempo the slower take has about
    1.56 times the nodes of the faster; with it, 1.08 to 1.22 times (measured: the generated clips' noise adds speed
    to each, and a still hold at either end does not get shorter when the movement is faster)."""
    for movement in MOVEMENTS:
        (tmp_path / movement).mkdir()
        for speed in ("0.8", "1.25"):
            clip = generated / "demos" / movement / f"morris_{speed}.bvh"
            (tmp_path / movement / clip.name).symlink_to(clip)
    ratios = {}
    for tempo in (0.0, 2.0):
        motor = observer(generated, tmp_path, motor={"tempo": tempo}).motor
        for movement, takes in motor.takes().items():
            counts = sorted(len(take) + 2 for take in takes)  # the ends are hubs
            ratios[tempo, movement] = counts[1] / counts[0]
    for movement in MOVEMENTS:  # the generated clips' noise and the holds at their ends keep it from 1 exactly
        assert ratios[0.0, movement] == pytest.approx(1.25 / 0.8, rel=0.05)
        assert ratios[2.0, movement] <= 1.25


def test_path_search_samples_a_demonstration_at_its_own_tempo(generated, fast):
    """A demonstration performed 2.5 times as slowly has about 1 / 2.5 of the frequency, and is sampled at about
    1 / 2.5 of the rate, so both are about as many samples (without tempo, 2.5 times as many; the limit, 3 here, is not reached: the wave's own frequency is near the
    repertoire's median). The demonstration is the posegraph's own wave played (its nodes interpolated), so that
    nothing in it, not even noise, keeps its speed when it is slowed."""
    character = observer(generated, fast, motor={"tempo": 3.0})
    motor, root = character.motor, character.body.root_index

    def played(speed):
        m = motor.play_path(next(p for n, p in motor.paths.items() if n.startswith("wave")), speed=speed)
        return Motion(m.positions - m.positions[:, root:root + 1], m.fps, m.parts)

    own, slower = (character.matcher.samples(played(s))[0] for s in (1.0, 0.4))
    assert 1.0 <= len(slower) / len(own) <= 1.2  # measured 17 / 15: sampled at 10 a second, the slower play's
    # steps cut fewer of the nodes' corners
    plain = observer(generated, fast).matcher
    assert len(plain.samples(played(0.4))[0]) == round(played(0.4).duration * motor.node_rate)  # at the node rate
    assert len(plain.samples(played(0.4))[0]) / len(plain.samples(played(1.0))[0]) == pytest.approx(2.5, rel=0.05)


def test_a_movement_performed_much_slower_than_ones_own_is_followed_with_tempo(generated, fast):
    """Scenario: the repertoire is Morris's fastest takes (1.25); each of his movements at speed 0.8 is performed
    another 2.5 times as slowly (3.9 times slower than the repertoire's). The template's search follows a movement
    down to half its own speed (``max_stay = 1``), and recognises each by most of its path all the same; with
    ``tempo`` each is recognised nearer than without (the demonstration is sampled at its own tempo, as the takes
    are)."""
    profile = load_profile(generated / "profile.toml")
    template = {"per_movement": True, "max_stay": 1, "max_distance": 1.0}
    answers = {}
    for tempo in (0.0, 2.0):
        character = observer(generated, fast, motor={"tempo": tempo}, matcher=template)
        for movement in MOVEMENTS:
            motion = slowed(profile.read(generated / "demos" / movement / "morris_0.8.bvh"), 2.5)
            match = Observer(character, profile.body, motion.fps).classify(motion).match
            answers[tempo, movement] = (match.movement, match.details["mean_distance"])
    for movement in MOVEMENTS:
        assert answers[2.0, movement][0] == movement
        assert answers[2.0, movement][1] < answers[0.0, movement][1]  # measured 0.011-0.016 against 0.013-0.020
