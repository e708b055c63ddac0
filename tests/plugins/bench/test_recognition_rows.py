"""``likeme bench recognition``'s item rows say why: the matcher's nearest movement, its score and its threshold."""
import math

import pytest

from plugins.bench.data import make_data
from plugins.bench.mocap import recognition
from toolkit.manager import create_plugin_manager
from toolkit.recordings.profile import load_profile


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("generated"), seed=11, streams=1, per_stream=2)


def test_each_row_holds_the_score_and_threshold_the_answer_was_decided_on(generated):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(generated / "profile.toml")
    result = recognition(pm, profile, generated / "repertoire", generated / "demos", ["dtw"],
                         settings={"matcher": {"decision": "calibrated"}}, protocol="open")
    rows = result["items"]
    assert rows and all(math.isfinite(r["score"]) and math.isfinite(r["threshold"]) for r in rows)
    for row in rows:  # unknown exactly where the score is above the threshold; the nearest named either way
        assert (row["recognised"] == "unknown") == (row["score"] > row["threshold"]), row
        assert row["nearest"] and row["nearest"] != row["movement"]  # the movement itself was left out
    assert any(r["recognised"] == "unknown" for r in rows)


def test_a_decision_without_a_threshold_leaves_it_empty(generated):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(generated / "profile.toml")
    rows = recognition(pm, profile, generated / "repertoire", generated / "demos", ["dtw"])["items"]
    assert all(r["recognised"] == r["nearest"] != "unknown" for r in rows)  # a DTW 1-NN: always the nearest
    assert all(math.isfinite(r["score"]) and r["score"] >= 0 and r["threshold"] is None for r in rows)
