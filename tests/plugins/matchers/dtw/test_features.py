"""What dtw warps (its ``features``): every part's positions, or issue 34's baselines on real people, the parts'
positions and velocities over body size, or their velocities alone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.comparison import HORIZON, sequence_size
from plugins.matchers.dtw import BodyMotion, Positions
from plugins.lib.velocity import derivative
from tests.plugins.matchers.hands import HANDS, LOW_RAISE
from toolkit import ConfigError, load_character

FPS = 30.0


def _observer(write, pm, **params):
    table = "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in params.items())
    return load_character(write("hands.toml", HANDS + f'\n[matcher]\nplugin = "dtw"\nstride = 1\n{table}'), pm)


def _low_raise(write, pm):
    """A raise held where the observer's wave is held (issue 34's low style): the demonstrator's own movement."""
    demonstrator = load_character(write("demonstrator.toml", HANDS + LOW_RAISE), pm)
    return demonstrator.motor.perform("low_raise", fps=FPS).root_relative(demonstrator.body.root)


@pytest.mark.parametrize(("features", "answer"), [("positions", "wave"), ("velocity", "raise")])
def test_a_raise_held_where_a_wave_is_held_is_a_raise_only_to_the_velocities(write, pm, features, answer):
    """Positions see where the hand is held, the wave's place; velocities see the hand lift and stay, a raise."""
    observer = _observer(write, pm, features=features)
    assert observer.matcher.match(_low_raise(write, pm)).movement == answer


def test_the_parts_compared_are_named_and_an_unknown_one_is_a_clear_error(write, pm):
    observer = _observer(write, pm, features="velocity", parts=["hand"])
    assert observer.matcher.features.parts.tolist() == [observer.body.index("hand")]
    assert observer.matcher.match(_low_raise(write, pm)).movement == "raise"
    with pytest.raises(ConfigError, match="unknown body part 'wrist'") as error:
        _observer(write, pm, features="velocity", parts=["hand", "wrist"])
    assert "hand" in str(error.value)


def test_a_distance_in_metres_is_refused_for_features_in_body_sizes(write, pm):
    with pytest.raises(ConfigError, match="max_distance"):
        load_character(write("hands.toml", HANDS + '\n[matcher]\nplugin = "dtw"\nfeatures = "motion"\n'
                                                   "[matcher.distance]\nmax_distance = 0.2\n"), pm)


poses = arrays(np.float64, (12, 4, 3), elements=st.floats(-1.0, 1.0))


@settings(max_examples=50, deadline=None)
@given(poses, st.floats(0.3, 3.0), arrays(np.float64, (3,), elements=st.floats(-1.0, 1.0)))
def test_motion_is_in_body_sizes_and_velocity_blind_to_where_a_part_is_held(rel, scale, offset):
    """A body ``scale`` times as big moving alike has the same series; a part held elsewhere throughout changes
    its positions, never its velocities."""
    rel = rel - rel[:, :1]
    parts = np.arange(4)
    motion, velocity = (BodyMotion(1, parts, 0, parts, positions=p) for p in (True, False))
    np.testing.assert_allclose(motion.series(rel * scale, FPS), motion.series(rel, FPS), rtol=1e-7, atol=1e-9)
    moved = rel.copy()
    moved[:, 2] += offset
    size, moved_size = (sequence_size(x, np.ones(x.shape[:2], dtype=bool)) for x in (rel, moved))
    if size > 1e-6 and moved_size > 1e-6:
        np.testing.assert_allclose(velocity.series(moved, FPS) * moved_size, velocity.series(rel, FPS) * size,
                                   rtol=1e-7, atol=1e-9)


def test_each_frame_is_the_positions_then_the_velocities_times_the_horizon_over_the_body_size():
    rng = np.random.default_rng(3)
    rel = rng.normal(size=(20, 4, 3))
    rel[:, 0] = 0.0
    size = sequence_size(rel, np.ones((20, 4), dtype=bool))
    parts = np.array([1, 3])
    got = BodyMotion(2, parts, 0, np.arange(4), positions=True).series(rel, FPS)
    expected = np.concatenate([rel[:, parts] / size, derivative(rel, FPS)[:, parts] * HORIZON / size], axis=1)
    np.testing.assert_allclose(got, expected[::2].reshape(10, -1))
    assert Positions(2).series(rel, FPS).tolist() == rel[::2].reshape(10, -1).tolist()


def test_a_fingers_joint_angle_is_neither_compared_nor_sized_as_a_position(write, pm):
    """A finger is a joint angle (docs/formats.md): not among the parts compared by default, an error when named,
    and left out of the body size and of the root's subtraction."""
    fingered = HANDS.replace('"hand"]', '"hand", "index"]')
    fingered = fingered.replace("[motor]", '[body.hands.right]\nwrist = "hand"\nfingers = ["index"]\n\n[motor]')
    fingered = fingered.replace('hand = [0.3, 1.0, 0.0]', 'hand = [0.3, 1.0, 0.0]\nindex = [0.2, 0.0, 0.0]')
    table = '\n[matcher]\nplugin = "dtw"\nfeatures = "motion"\n'
    observer = load_character(write("fingered.toml", fingered + table), pm)
    features = observer.matcher.features
    assert features.parts.tolist() == features.sized.tolist() == [0, 1, 2, 3, 4]
    rel = np.random.default_rng(1).normal(size=(8, 6, 3))
    bent = rel.copy()
    bent[:, 5] *= 3.0  # the finger bent further: nothing compared changes
    assert features.series(bent, FPS).tolist() == features.series(rel, FPS).tolist()
    with pytest.raises(ConfigError, match="'index' is a finger's joint angle") as error:
        load_character(write("fingered.toml", fingered + table + 'parts = ["hand", "index"]\n'), pm)
    assert "available" in str(error.value) and "index" not in str(error.value).split("available")[1]
