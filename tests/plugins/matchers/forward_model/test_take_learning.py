"""True imitation learning while following real people (plugins.matchers.forward_model.learning.TakeLearning;
K&G 2006, §4.3): a demonstration no take predicts becomes the take of a new movement, which predicts the next
performance of it, and is saved and loaded with the motor command graph.

On the project's generated recordings: Max knows four movements; Morris sits down and jumps.
"""

from __future__ import annotations

import pytest

from plugins.bench.data import make_data
from toolkit import create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile

KNOWN = ("nod", "wave", "bow", "clap")


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture(scope="module")
def generated(tmp_path_factory, pm):
    data = make_data(pm, tmp_path_factory.mktemp("take-learning"), seed=6, streams=0, per_stream=4)
    known = tmp_path_factory.mktemp("known")
    for movement in KNOWN:
        (known / movement).symlink_to(data / "repertoire" / movement, target_is_directory=True)
    return data, known, load_profile(data / "profile.toml")


def watcher(pm, generated, learn):
    data, known, profile = generated
    settings = {"matcher": {"learn": True}} if learn else {}
    character = compose_observer(pm, profile, known, matcher="forward-model", settings=settings)
    assert character.matcher.params["comparison"] == "motion+strokes"
    return character, Observer(character, profile.body, 30.0)


def demo(generated, movement, who="morris_1.0"):
    data, _, profile = generated
    return profile.read(data / "demos" / movement / f"{who}.bvh", None)


def test_an_unknown_demonstration_is_learned_and_predicts_the_next_performance(pm, generated):
    character, watch = watcher(pm, generated, learn=True)
    first = watch.classify(demo(generated, "sit", "morris_0.8"))
    assert first.movement == "learned-1" and first.match.details["learned"]
    assert first.match.details["nearest"] in KNOWN  # what it was rejected as, kept
    assert "learned-1" in character.motor.movements()
    assert [len(t) for t in character.motor.takes().values()] == [1] * 5
    again = watch.classify(demo(generated, "sit", "morris_1.0"))  # another performance: predicted, not learned
    assert again.movement == "learned-1" and "learned" not in again.match.details
    assert watch.classify(demo(generated, "jump")).movement == "learned-2"
    assert watch.classify(demo(generated, "nod")).movement == "nod"  # what it knew, still known


def test_what_is_learned_is_saved_and_loaded_with_the_motor_system(pm, generated):
    character, watch = watcher(pm, generated, learn=True)
    watch.classify(demo(generated, "sit", "morris_0.8"))
    state = character.motor.get_state()
    fresh, watch_fresh = watcher(pm, generated, learn=False)
    assert watch_fresh.classify(demo(generated, "sit")).movement is None  # it has not seen anyone sit
    fresh.motor.set_state(state)
    assert "learned-1" in fresh.motor.takes()
    assert watch_fresh.classify(demo(generated, "sit")).movement == "learned-1"


def test_an_observer_that_does_not_learn_answers_unknown(pm, generated):
    character, watch = watcher(pm, generated, learn=False)
    answer = watch.classify(demo(generated, "sit", "morris_0.8"))
    assert answer.movement is None and answer.match.nearest in KNOWN
    assert sorted(character.motor.movements()) == sorted(KNOWN)
