"""Decisions relative to the body: length parameters written for one height, scaled to the observer's own
(issue 18: the same character file on a mouse, a humanoid and a Kinect skeleton), and the leave-one-group-out
recognition protocol.
"""

from __future__ import annotations

import math

import pytest

from toolkit import ConfigError, create_plugin_manager
from toolkit.observe import compose_observer
from toolkit.recordings.profile import load_profile


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


PAPER = {"matcher": {"comparison": "poses", "search": "k-best", "decision": "distance"}}
"""The papers' path search (eq. 1 in metres, the k best paths, max_distance), whose lengths are scaled."""


def test_length_parameters_scale_with_the_observers_height_and_nothing_else_does(generated, pm):
    from toolkit.params import length_names

    profile = load_profile(generated / "profile.toml")
    plain = compose_observer(pm, profile, generated / "repertoire", settings=PAPER)
    halved = compose_observer(pm, profile, generated / "repertoire", lengths_for_height=plain.height / 2,
                              settings=PAPER)
    assert plain.length_scale == pytest.approx(1.0, abs=1e-12) and halved.length_scale == pytest.approx(2.0)
    for key in ("matcher", "segmenter"):
        before, after = getattr(plain, key), getattr(halved, key)
        lengths = length_names(type(after).parameters)
        assert lengths, f"the {key} declares its lengths"
        for path in lengths:
            a, b = after.params, before.params
            for k in path:
                a, b = a[k], b[k]
            assert a == pytest.approx(2 * b), path
        assert dict(after.declared) == dict(before.declared)  # as written (the plain one scales by 1, up to rounding)
    assert dict(halved.motor.params) == dict(plain.motor.params)  # the motor system measures the body itself
    assert ("distance", "max_distance") in length_names(type(plain.matcher).parameters)


def test_the_same_observer_file_recognises_a_body_three_times_as_tall(generated, giant, pm):
    """Every eq. 1 distance of the giant is ten times Max's: with the papers' path search, in metres the thresholds
    written for Max reject almost everything; written for Max's height and scaled to the giant's, the answers are
    Max's own. The observer template's comparison is in the demonstrator's own body sizes and its decision
    calibrated: the giant gets Max's answers with no height given at all."""
    from plugins.bench.mocap import recognition

    small = load_profile(generated / "profile.toml")
    height = compose_observer(pm, small, generated / "repertoire").height

    def answers(profile, lengths_for_height, settings=PAPER):
        result = recognition(pm, profile, generated / "repertoire", generated / "demos", ["path-search"],
                             observer={"lengths_for_height": lengths_for_height}, settings=settings)
        return [item["recognised"] for item in result["items"]], result["plugins"][0]["accuracy"]

    own, accuracy = answers(small, height)
    assert accuracy > 0.8
    scaled, _ = answers(giant, height)
    metres, metres_accuracy = answers(giant, None)
    assert sum(a == b for a, b in zip(own, scaled)) >= 0.95 * len(own)
    assert metres_accuracy < 0.5 * accuracy and metres.count("unknown") > 0.5 * len(metres)
    template, _ = answers(small, None, settings=None)
    giant_template, _ = answers(giant, None, settings=None)
    assert giant_template == template


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


@pytest.mark.benchmark
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


# -- what path search needs of a posegraph -------------------------------------------------------------------


def test_the_exact_search_needs_a_posegraph_that_knows_its_takes(generated, pm):
    """A posegraph with only what the paper needs (a third party's) serves the papers' path search, but not the
    per-movement search, the motion comparison or the calibrated decision, each refused by its key."""
    from types import SimpleNamespace

    from plugins.matchers.path_search import PathSearch, PoseGraph
    from toolkit.components import protocol_members

    profile = load_profile(generated / "profile.toml")
    observer = compose_observer(pm, profile, generated / "repertoire")
    motor = observer.motor
    bare = SimpleNamespace(**{name: getattr(motor, name) for name in protocol_members(PoseGraph)})
    owner = SimpleNamespace(motor=bare, body=observer.body)
    PathSearch().attach(owner)  # the paper's search and threshold need no takes
    for key, value in (("search", "per-movement"), ("decision", "calibrated")):
        with pytest.raises(ConfigError, match="takes") as err:
            PathSearch(**{key: value}).attach(owner)
        assert err.value.key == (key,)
