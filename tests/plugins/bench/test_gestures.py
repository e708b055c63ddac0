"""The hand gestures ``likeme bench make-gestures`` writes: the layout the recognition protocols read, a Kinect's
skeleton through its profile, and the properties the data set stands for (a wave's reversals, held places the
styles move, tempi 3.5 times apart)."""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.gestures import JOINTS, MOVEMENTS, STYLES, Performer, gesture, make_gestures
from toolkit.recordings.profile import load_profile

_J = {name: i for i, name in enumerate(JOINTS)}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return make_gestures(tmp_path_factory.mktemp("gestures"), seed=3, performers=2, takes=2)


def _person(seed: int = 0) -> Performer:
    return Performer.draw(np.random.default_rng(seed))


def _reversals(hand: np.ndarray, fps: float = 30.0) -> int:
    """Sign changes of a hand's sideways velocity while it is held up (within 8 cm of its highest), where it moves
    faster than 0.15 m/s (a hold's tremor is not one)."""
    held = hand[:, 1] > hand[:, 1].max() - 0.08
    v = np.gradient(hand[:, 0])[held] * fps
    signs = np.sign(v[np.abs(v) > 0.15])
    return int((signs[1:] != signs[:-1]).sum())


def test_the_folder_holds_the_first_performers_normal_takes_as_the_repertoire_and_every_other_as_demos(folder):
    for movement in MOVEMENTS:
        own = sorted(p.name for p in (folder / "repertoire" / movement).iterdir())
        assert own == [f"gestures_{movement.replace('_', '-')}_normal_p1_00{k}.csv" for k in (1, 2)]
        demos = sorted(p.name for p in (folder / "demos" / movement).iterdir())
        assert len(demos) == 2 * len(STYLES) - 1
        assert all(f"_{style}_p2_001.csv" in " ".join(demos) for style in STYLES)


def test_every_file_reads_through_the_profile_with_its_lost_joints_not_visible(folder):
    profile = load_profile(folder / "profile.toml")
    files = sorted(folder.glob("*/*/*.csv"))
    assert len(files) == len(MOVEMENTS) * (2 + 2 * len(STYLES) - 1)
    motion = profile.read(files[0])
    assert motion.fps == pytest.approx(30.0)
    assert len(motion.parts) == 19  # the Kinect's 20 joints but the spine
    assert 0.0 < (~motion.visible).mean() < 0.1
    # standing on the floor: the feet near y = 0, the head 1.4-2 m above them
    seen = motion.visible[:, motion.parts.index("head")]
    head = motion.positions[seen, motion.parts.index("head"), 1]
    assert 1.3 < np.median(head) < 2.0


def test_the_same_seed_writes_the_same_files_whatever_wrote_them(tmp_path, folder):
    again = make_gestures(tmp_path / "again", seed=3, performers=2, takes=2, jobs=2)
    for path in sorted(folder.glob("*/*/*.csv"))[:5]:
        assert (again / path.relative_to(folder)).read_bytes() == path.read_bytes()


def test_a_wave_reverses_the_hand_many_times_and_a_raise_at_most_once():
    p, rng = _person(1), np.random.default_rng(0)
    for style in ("normal", "low", "high", "slow"):
        wave = gesture("wave_left", STYLES[style], p, rng)
        lift = gesture("raise_left", STYLES[style], p, rng)
        assert _reversals(wave[:, _J["HandLeft"]]) >= 3
        assert _reversals(lift[:, _J["HandLeft"]]) <= 1
        # the other hand hangs still
        assert np.ptp(wave[:, _J["HandRight"], 1]) < 0.03


def test_the_styles_move_where_the_hand_is_held_so_that_places_alone_confuse_waves_and_raises():
    p, rng = _person(2), np.random.default_rng(0)

    def held(movement, style):
        q = gesture(movement, STYLES[style], p, rng, vary=0.0)
        return q[len(q) // 2, _J["HandLeft"]] - q[len(q) // 2, _J["ShoulderLeft"]]

    normal_wave, normal_raise = held("wave_left", "normal"), held("raise_left", "normal")
    # a low raise is held nearer a normal wave than a normal raise; a high wave nearer a normal raise than a wave
    assert np.linalg.norm(held("raise_left", "low") - normal_wave) < np.linalg.norm(
        held("raise_left", "low") - normal_raise)
    assert np.linalg.norm(held("wave_left", "high") - normal_raise) < np.linalg.norm(
        held("wave_left", "high") - normal_wave)


def test_fast_and_slow_takes_lie_more_than_three_times_apart_in_duration():
    p, rng = _person(3), np.random.default_rng(0)
    fast = [len(gesture(m, STYLES["fast"], p, rng, vary=0.0)) for m in MOVEMENTS]
    slow = [len(gesture(m, STYLES["slow"], p, rng, vary=0.0)) for m in MOVEMENTS]
    # the rests before and after do not scale with the tempo; the movement itself does
    rest = 2 * 0.6 * 30
    assert all((s - rest) / (f - rest) > 3.0 for f, s in zip(fast, slow))


def test_performers_differ_in_size_and_the_body_scales_with_them():
    rng = np.random.default_rng(0)
    people = [Performer.draw(rng) for _ in range(20)]
    sizes = np.array([p.size for p in people])
    assert sizes.min() >= 1.55 and sizes.max() <= 1.95 and np.ptp(sizes) > 0.2
    for p in people[:3]:
        q = gesture("raise_both", STYLES["normal"], p, np.random.default_rng(1))
        assert q[0, _J["Head"], 1] == pytest.approx(0.94 * p.size, rel=0.02)
        # the arms keep their lengths while they move
        upper = np.linalg.norm(q[:, _J["ElbowLeft"]] - q[:, _J["ShoulderLeft"]], axis=1)
        assert np.allclose(upper, p.upper_arm * p.size, rtol=1e-6)
