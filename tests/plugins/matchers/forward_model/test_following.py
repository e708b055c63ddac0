"""The forward model following real people (plugins.matchers.forward_model.following): every take played by its
commands, followed by time warping with the shared comparison and calibrated decision (K&G 2006, §4.4).

On the project's generated recordings (Max's movements as the repertoire, one take each; Morris's versions as
demonstrations): the predictions are the takes' commands played; the calibration leaves each take out; a familiar
movement is committed to early; rows given at once give what rows fed one by one give; a movement that begins as
one and goes on as another is a deviation.
"""

from __future__ import annotations

import types

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.data import make_data
from plugins.bench.mocap import _streams
from plugins.matchers.forward_model.following import RATE, RECENT, Following
from toolkit import Matcher, Motion, create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from plugins.matchers.pacing import PRIOR
from tests.plugins.matchers.reference import followed_left_out_scores


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture(scope="module")
def generated(tmp_path_factory, pm):
    data = make_data(pm, tmp_path_factory.mktemp("following"), seed=6, streams=2, per_stream=4)
    return data, load_profile(data / "profile.toml")


@pytest.fixture(scope="module")
def observer(generated, pm):
    data, profile = generated
    character = compose_observer(pm, profile, data / "repertoire", matcher="forward-model")
    assert character.matcher.params["comparison"] == "motion+strokes"  # the observer template's
    return character


def following(character) -> Following:
    return character.matcher.match.__self__


def test_every_take_is_predicted_by_its_commands_at_the_sample_rate(observer):
    f = following(observer)
    takes = observer.motor.takes()
    chains = f.prediction.chains
    assert len(chains) == sum(len(t) for t in takes.values())
    for c, (movement, take) in enumerate(zip(chains.movements, f.prediction.takes)):
        edges = next(edges for edges, *_ in takes[movement])
        duration = sum(observer.motor.edge(e).duration for e in edges)
        assert len(take) == pytest.approx(duration * RATE, abs=len(edges) + 1)
        assert take.parts.shape[1:] == (len(observer.body.parts), 6)  # shape from the onset, and motion


def test_the_calibration_leaves_each_take_out(observer):
    """One take of each movement: each take's prediction followed against the other movements' (leave one movement
    out) as a demonstration is followed, at each take's pace, over its distance to standing still at that pace; no
    take of its own movement to leave out."""
    f = following(observer)
    p = f.prediction
    want = followed_left_out_scores(f.comparison, p.takes, p.frames, p.chains, PRIOR * RATE)
    assert f.decision.calibration.own == ()
    assert f.decision.calibration.other == pytest.approx(want)


def test_a_familiar_movement_is_committed_to_before_it_ends(observer, generated):
    """Max watching his own movements: each is committed to, most well before it ends (response facilitation)."""
    data, profile = generated
    watcher = Observer(observer, profile.body, 30.0)
    fractions = []
    for clip in sorted((data / "repertoire").glob("*/max.bvh"))[:12]:
        obs = watcher.classify(profile.read(clip, None))
        assert obs.movement == clip.parent.name
        fractions.append(obs.decision_fraction)
    assert np.median(fractions) < 0.5


def test_rows_given_at_once_give_what_rows_fed_one_by_one_give(observer, generated):
    """The watching loop gives a streaming matcher rows at once (replay) or one by one (observe after each): the
    same observations, the same commitments at the same frames, the same answers."""
    data, profile = generated
    streams = [profile.read(path, None) for path, _ in _streams(data / "streams")]
    matcher = observer.matcher
    streaming = matcher.replay
    runs = []
    for at_once in (True, False):
        if not at_once:
            matcher.replay = types.MethodType(Matcher.replay, matcher)  # observe after every row
        try:
            found = []
            for motion in streams:
                for o in Observer(observer, profile.body, motion.fps).watch(motion):
                    found.append((o.segment, o.movement, o.decided_at, repr(o.match)))
            runs.append(found)
        finally:
            matcher.replay = streaming
    assert runs[0] and runs[0] == runs[1]


def _wave_then_stretch(observer, generated, share: float):
    """The first ``share`` of Max's wave, then his stretch from where the wave was, followed as one demonstration:
    the forward model, what it decided while following (frame, match) and its answer at the end, and the cut."""
    data, profile = generated
    f = following(observer)
    first = profile.read(data / "repertoire" / "wave" / "max.bvh", None)
    second = profile.read(data / "repertoire" / "stretch" / "max.bvh", None)
    cut = int(share * first.n_frames)
    start = second.positions - second.positions[:1] + first.positions[cut - 1 : cut]
    joined = np.concatenate([first.positions[:cut], start])
    visible = np.concatenate([first.visible[:cut], second.visible])
    motion = Motion(joined, first.fps, first.parts, visible, joined)
    f.begin(motion.fps)
    events = f.add(motion.world, motion.visible)
    return f, events, f.conclude(motion.n_frames), cut


def test_a_movement_that_goes_on_as_another_is_a_deviation_and_the_other_is_committed_to(observer, generated):
    """The first two fifths of a wave, then a stretch: the forward model commits to the wave and, when the stretch
    prevails (it has been the nearest for :data:`RECENT` seconds), reports the wave's deviation (``stop``, K&G
    Fig. 3's "stop imitation") and commits to the stretch at that frame (Fig. 3: predict again, and imitate what
    prevails); at the end the stretch is the answer and its commitment stands."""
    f, events, final, cut = _wave_then_stretch(observer, generated, 0.4)
    assert [(m.movement, m.stop) for _, m in events] == [("wave", False), ("wave", True), ("stretch", False)]
    (commit, wave), (stop, stopped), (again, stretch) = events
    assert commit < cut < stop == again and stopped.reason == "deviation" and stopped.score > 0
    assert wave.decided_at < stretch.decided_at
    assert final is stretch  # the commitment stands: the answer on all of it is the stretch


def test_a_commitment_that_is_not_the_answer_at_the_end_is_replaced(observer, generated):
    """Eleven twentieths of a wave, then the stretch: the wave prevails for most of the demonstration and is committed
    to; the stretch comes nearest only on the last samples, too late to prevail, but the answer on all of it is the
    stretch: the commitment does not stand (the demonstration must end where the committed movement does, K&G
    §4.4): it is a deviation at the end, and the answer is the one at the end."""
    f, events, final, _ = _wave_then_stretch(observer, generated, 0.55)
    assert [(m.movement, m.stop) for _, m in events] == [("wave", False)]
    assert final.movement == "stretch" and final.decided_at is None
    assert f.committed is None and f.deviated and f.deviated_at == f.watched.n  # stopped at the end


def test_every_take_of_the_repertoire_is_its_own_movement_standing_still_too(observer, generated):
    """Max watching his own takes, each as one whole segment: every one is answered as itself. ``stand`` predicts
    no motion at all, so its score against standing still is 1 whatever is shown: it is judged by how little the
    demonstration moves (:class:`plugins.matchers.decision.Stillness`), and an answer decided on the last samples
    is reported rather than lost."""
    data, profile = generated
    watcher = Observer(observer, profile.body, 30.0)
    f = following(observer)
    assert f.stillness.still == {"stand"}
    answers = {}
    for clip in sorted((data / "repertoire").glob("*/max.bvh")):
        answers[clip.parent.name] = watcher.classify(profile.read(clip, None)).movement
    assert answers == {name: name for name in answers}
    stand = watcher.classify(profile.read(data / "repertoire" / "stand" / "max.bvh", None)).match
    assert stand.measure == f.stillness.measure and stand.score <= stand.threshold == f.stillness.limit


def test_a_moving_demonstration_is_not_the_still_movement(observer, generated):
    """A wave moves far more than half the least moving movement: were standing still the nearest, it would not
    be ``stand``; a demonstration that does not move is ``stand``, and never a moving movement by stillness."""
    data, profile = generated
    f = following(observer)
    wave = profile.read(data / "repertoire" / "wave_both" / "max.bvh", None)
    f.begin(wave.fps)
    f.add(wave.world if wave.world is not None else wave.positions, wave.visible)
    f.conclude(wave.n_frames)
    assert f.moving > f.stillness.limit
    assert not f.stillness.holds("stand", f.moving)
    assert f.stillness.holds("stand", 0.0) and not f.stillness.holds("nod", 0.0)


def test_a_part_hidden_at_the_onset_is_measured_from_where_it_was_first_seen(observer, generated):
    """The onset shape is each part's position since the movement began; a part a tracker did not see in the first
    frames begins where it was first seen (before: at 0, its whole root-relative position read as movement)."""
    from plugins.matchers.comparison import Motion as Comparison
    from plugins.matchers.forward_model.following import Watched

    data, profile = generated
    motion = profile.read(data / "demos" / "wave" / "morris_1.0.bvh")
    hand = profile.body.index("right_hand")
    world = motion.positions.copy()
    world[:7, hand] = np.nan
    visible = np.isfinite(world).all(axis=-1)
    watched = Watched(observer.body, motion.fps, Comparison(shape="onset"))
    watched.add(world, visible)
    frames = watched.frames(watched.due(True))
    whole = Watched(observer.body, motion.fps, Comparison(shape="onset"))
    whole.add(motion.positions, np.ones(visible.shape, dtype=bool))
    later = whole.frames(whole.due(True))
    assert watched.size == pytest.approx(whole.size, rel=0.02)  # the body's size from the parts seen
    seen = frames.seen[:, hand]
    assert not seen[0] and seen[3:].all()
    # seen, the hand is where it has gone since it was first seen (frame 7), not since frame 0 where it was hidden
    since = (whole.relative[7, hand] - whole.relative[0, hand]) / whole.size
    np.testing.assert_allclose(frames.parts[seen, hand, :3] * watched.size / whole.size,
                               later.parts[seen, hand, :3] - since, atol=1e-9)


@settings(max_examples=15, deadline=None)
@given(hidden=st.integers(0, 40), seed=st.integers(0, 2**16))
def test_the_root_lost_at_the_onset_gives_the_same_answers_however_the_frames_come(observer, generated, hidden, seed):
    """The root hidden for the first frames, nothing is root-relative, and the body's size waits for the first
    frames with two parts seen: fed at once or in random blocks (as a bounded working memory gives them), the same
    decisions at the same frames and the same answer (before: a size measured on whatever block came first)."""
    data, profile = generated
    motion = profile.read(data / "demos" / "wave" / "morris_1.0.bvh")
    world = motion.positions.copy()
    world[:hidden, profile.body.root_index] = np.nan
    visible = np.isfinite(world).all(axis=-1)
    rng = np.random.default_rng(seed)
    cuts = np.sort(rng.choice(np.arange(1, len(world)), size=6, replace=False)).tolist()
    f = following(observer)
    runs = []
    for blocks in ([0, len(world)], [0, *cuts, len(world)]):
        f.begin(motion.fps)
        events = []
        for a, b in zip(blocks[:-1], blocks[1:]):
            events += [(frame, repr(match)) for frame, match in f.add(world[a:b], visible[a:b])]
        runs.append((events, repr(f.conclude(motion.n_frames)), f.watched.size, f.watched.first))
    assert runs[0] == runs[1]
    assert runs[0][2] > 0 and runs[0][3] >= hidden + f.watched.delay  # measured once the root was found
    assert all(frame + f.watched.delay >= hidden for frame, _ in runs[0][0])


def test_the_window_fits_are_the_derivative_of_the_window():
    """The weights a live demonstration's velocities are taken with near its ends (``_window_fits``) give what the
    Savitzky-Golay derivative of the first or last window's frames gives there (scipy's own edge fit, to rounding),
    and their middle row is the centred filter itself."""
    from scipy.signal import savgol_coeffs

    from plugins.lib.velocity import derivative
    from plugins.matchers.forward_model.following import _window_fits

    rng = np.random.default_rng(3)
    for fps in (24.0, 30.0, 60.0, 120.0):
        fits = _window_fits(max(5, int(round(0.2 * fps)) | 1), fps)
        taps = len(fits)
        window = rng.normal(size=(taps, 4, 3)) + np.linspace(0.0, 1.0, taps)[:, None, None] ** 2
        expected = derivative(window, fps)
        np.testing.assert_allclose(np.einsum("kt,tpd->kpd", fits, window), expected, rtol=1e-10,
                                   atol=1e-10 * np.abs(expected).max())
        np.testing.assert_array_equal(fits[taps // 2], savgol_coeffs(taps, 2, deriv=1, delta=1.0 / fps, use="dot"))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), cut=st.integers(1, 60))
def test_parts_hidden_in_a_block_are_held_as_frame_by_frame(observer, generated, seed, cut):
    """Each part hidden by a tracker is held where it was last seen whether the frames come in one block, in two,
    or one by one (the block's holding is vectorised; frame by frame it is one frame's)."""
    from plugins.matchers.comparison import Motion as Comparison
    from plugins.matchers.forward_model.following import Watched

    data, profile = generated
    motion = profile.read(data / "demos" / "wave" / "morris_1.0.bvh")
    rng = np.random.default_rng(seed)
    visible = rng.random(motion.visible.shape) > 0.3
    visible[:, profile.body.root_index] = rng.random(len(visible)) > 0.1
    world = np.where(visible[..., None], motion.positions, np.nan)
    blocks, halves, single = (Watched(observer.body, motion.fps, Comparison(shape="onset")) for _ in range(3))
    blocks.add(world, visible)
    halves.add(world[:cut], visible[:cut])
    halves.add(world[cut:], visible[cut:])
    for i in range(len(world)):
        single.add(world[i : i + 1], visible[i : i + 1])
    for other in (halves, single):
        np.testing.assert_array_equal(blocks.seen[: blocks.n], other.seen[: other.n])
        np.testing.assert_allclose(blocks.relative[: blocks.n], other.relative[: other.n], rtol=0, atol=1e-12)
        np.testing.assert_array_equal(blocks.origin, other.origin)
