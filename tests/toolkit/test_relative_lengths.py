"""Decisions relative to the body: length parameters written for one height, scaled to the observer's own
(issue 18: the same character file on a mouse, a humanoid and a Kinect skeleton), and the leave-one-group-out
recognition protocol.
"""

from __future__ import annotations

import math

import pytest

from toolkit import ConfigError, create_plugin_manager
from toolkit.observe import compose_observer
from toolkit.profile import load_profile


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    from plugins.bench.data import make_data

    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("generated"), seed=7, streams=1, per_stream=3)


@pytest.fixture(scope="module")
def giant(generated, tmp_path_factory):
    """The generated recordings read as a body ten times as tall (metres per unit 10: a humanoid beside a mouse)."""
    text = (generated / "profile.toml").read_text().replace('units = "metre"', "units = 10.0")
    assert "units = 10.0" in text
    path = tmp_path_factory.mktemp("giant") / "profile.toml"
    path.write_text(text)
    return load_profile(path)


def test_length_parameters_scale_with_the_observers_height_and_nothing_else_does(generated, pm):
    profile = load_profile(generated / "profile.toml")
    plain = compose_observer(pm, profile, generated / "repertoire")
    halved = compose_observer(pm, profile, generated / "repertoire", lengths_for_height=plain.height / 2)
    assert plain.length_scale == 1.0 and halved.length_scale == pytest.approx(2.0)
    for key in ("matcher", "segmenter"):
        before, after = getattr(plain, key), getattr(halved, key)
        lengths = {p.name for p in type(after).parameters if p.length}
        assert lengths, f"the {key} declares its lengths"
        for name, value in after.params.items():
            expected = 2 * before.params[name] if name in lengths else before.params[name]
            assert value == pytest.approx(expected), name
        assert dict(after.declared) == dict(before.params)  # as written
    assert dict(halved.motor.params) == dict(plain.motor.params)  # the motor system measures the body itself
    assert "max_distance" in {p.name for p in type(plain.matcher).parameters if p.length}


def test_the_same_observer_file_recognises_a_body_three_times_as_tall(generated, giant, pm):
    """Every eq. 1 distance of the giant is ten times Max's: in metres the thresholds written for Max reject
    almost everything; written for Max's height and scaled to the giant's, the answers are Max's own."""
    from plugins.bench.mocap import recognition

    small = load_profile(generated / "profile.toml")
    height = compose_observer(pm, small, generated / "repertoire").height

    def answers(profile, lengths_for_height):
        result = recognition(pm, profile, generated / "repertoire", generated / "demos", ["path-search"],
                             observer={"lengths_for_height": lengths_for_height})
        return [item["recognised"] for item in result["items"]], result["plugins"][0]["accuracy"]

    own, accuracy = answers(small, height)
    assert accuracy > 0.8
    scaled, _ = answers(giant, height)
    metres, metres_accuracy = answers(giant, None)
    assert sum(a == b for a, b in zip(own, scaled)) >= 0.95 * len(own)
    assert metres_accuracy < 0.5 * accuracy and metres.count("unknown") > 0.5 * len(metres)


@pytest.mark.parametrize("value", [0, -1.0, "tall", True, math.inf, math.nan])
def test_a_height_that_is_not_a_positive_number_is_refused_by_name(value, pm):
    from toolkit.character import compose_character

    table = {"character": {"name": "x", "lengths_for_height": value},
             "body": {"parts": ["root", "a", "b"], "root": "root", "facing": {"left": "a", "right": "b"}},
             "motor": {"plugin": "keyframe", "poses": {"rest": [[0, 0, 0], [0.1, 0, 0], [-0.1, 0, 0]]},
                       "movements": {}}}
    with pytest.raises(ConfigError) as err:
        compose_character(table, pm)
    assert err.value.key == ("character", "lengths_for_height")
    assert "positive number" in err.value.expected


def test_leave_one_group_out_classifies_each_group_against_the_others(generated, pm):
    """The demos at three speeds (morris_0.8, morris_1.0, morris_1.25) as three groups: each speed's clips are
    classified by a repertoire of the other two speeds' clips."""
    from plugins.bench.mocap import recognition

    profile = load_profile(generated / "profile.toml")
    result = recognition(pm, profile, generated / "demos", None, ["dtw"], protocol="groups",
                         group=r"morris_([0-9.]+)\.bvh$")
    groups = {item["group"] for item in result["items"]}
    assert groups == {"0.8", "1.0", "1.25"}
    demos = sorted((generated / "demos").glob("*/*.bvh"))
    assert len(result["items"]) == len(demos)
    # a clip is never its own template: the nearest take is another speed of the same movement, not a copy
    assert all(item["confidence"] < 1.0 for item in result["items"])
    assert result["plugins"][0]["accuracy"] > 0.8


@pytest.mark.parametrize("group, problem", [(None, "needs a pattern"), ("morris", "no capture group"),
                                            (r"max_(\d)", "without a group"), (r"(morris)_", "1 group found"),
                                            ("(", "not a regular expression")])
def test_a_group_pattern_that_cannot_split_the_clips_is_refused(generated, pm, group, problem):
    from plugins.bench.mocap import recognition

    profile = load_profile(generated / "profile.toml")
    with pytest.raises(ConfigError, match=problem) as err:
        recognition(pm, profile, generated / "demos", None, ["dtw"], protocol="groups", group=group)
    assert err.value.key == ("group",)


# -- path search relative to the repertoire's spread between takes -------------------------------------------


@pytest.fixture(scope="module")
def takes_observer(generated):
    """An observer whose repertoire is Morris's demos: three takes of each movement (three speeds)."""
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(generated / "profile.toml")
    return compose_observer(pm, profile, generated / "demos", settings={"matcher": {"spread": 2.0}})


def test_every_movement_of_several_takes_has_a_spread_and_a_threshold_from_it(takes_observer):
    matcher = takes_observer.matcher
    matcher._refresh()
    takes = takes_observer.motor.takes()
    assert set(matcher.spreads) == {m for m, t in takes.items() if len(t) >= 2} == set(takes)
    for movement, spread in matcher.spreads.items():
        assert spread > 0
        assert matcher.threshold(movement) == pytest.approx(2.0 * spread)
    assert matcher.threshold("not a movement") == matcher.params["max_distance"]


def test_a_take_left_out_of_the_search_is_never_on_the_path(takes_observer):
    import numpy as np

    matcher = takes_observer.matcher
    matcher._refresh()
    index = {n: i for i, n in enumerate(matcher.node_names)}
    nodes = matcher.nodes_compared  # the poses as search compares them (with travel, one part more)
    for movement, takes in list(takes_observer.motor.takes().items())[:5]:
        own = np.array([index[n] for n in takes[0]])
        exclude = np.zeros(len(nodes), bool)
        exclude[own] = True
        path, cost, _ = matcher.search(nodes[own], np.ones(nodes[own].shape[:2], bool), None, exclude)
        assert not exclude[path].any() and np.isfinite(cost)
        free, free_cost, _ = matcher.search(nodes[own], np.ones(nodes[own].shape[:2], bool))
        assert free_cost == pytest.approx(0.0, abs=1e-9) and cost > 1e-6  # without the exclusion it finds itself


def test_spread_thresholds_accept_known_movements_and_reject_left_out_ones(generated, pm):
    """Max's own clips against three takes of Morris's: a movement in the repertoire is accepted within twice its
    spread between takes; with the movement left out, most are answered unknown."""
    from plugins.bench.mocap import recognition

    profile = load_profile(generated / "profile.toml")
    settings = {"matcher": {"spread": 2.0}}
    closed = recognition(pm, profile, generated / "demos", generated / "repertoire", ["path-search"],
                         settings=settings)["plugins"][0]
    opened = recognition(pm, profile, generated / "demos", generated / "repertoire", ["path-search"],
                         settings=settings, protocol="open")["plugins"][0]
    assert closed["accuracy"] > 0.8 and opened["rejection"] > 0.5


def test_spread_needs_a_motor_system_that_knows_its_takes(takes_observer):
    """A posegraph without takes() (a third party's) serves path search, but not its spread."""
    from types import SimpleNamespace

    from plugins.matchers.path_search import PathSearch, PoseGraph
    from toolkit.components import protocol_members

    motor = takes_observer.motor
    bare = SimpleNamespace(**{name: getattr(motor, name) for name in protocol_members(PoseGraph)})
    owner = SimpleNamespace(motor=bare, body=takes_observer.body)
    PathSearch().attach(owner)  # the paper's threshold needs no takes
    with pytest.raises(ConfigError, match="takes") as err:
        PathSearch(spread=2.0).attach(owner)
    assert err.value.key == ("spread",)
