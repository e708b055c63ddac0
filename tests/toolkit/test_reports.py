"""Every scenario through every report (issue 19): the text report, the JSON report and ``--save``, run in-process.

New scenario files in ``characters/scenarios/`` are covered automatically (the parameters are the files found there).
"""

from __future__ import annotations

import contextlib
import io
import json
import re

import pytest

from tests.conftest import CHARACTERS
from toolkit.report import _edges, _names, behaviour_sentence
from toolkit.state import read_state

SCENARIOS = sorted((CHARACTERS / "scenarios").glob("*.toml"))


@pytest.fixture(autouse=True)
def builtins_only(monkeypatch):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")


def likeme(*args) -> tuple[int, str, str]:
    """Run the likeme command in-process; (exit status, stdout, stderr)."""
    from toolkit.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main([str(a) for a in args])
        except SystemExit as exc:
            status = exc.code
    return status, out.getvalue(), err.getvalue()


def test_there_are_scenarios():
    assert len(SCENARIOS) >= 10


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_text_report(scenario):
    status, out, err = likeme("run", scenario)
    assert status == 0, err
    assert "Traceback" not in out + err and "went on without plugin" not in out
    assert re.search(r"^.+: \d+\.\d\d s, \d+ frames at [\d.]+ fps$", out, re.M)  # the title line
    assert out.count(" did: ") == out.count(" parts): ")  # every actor says what it did


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_json_report(scenario):
    status, out, err = likeme("run", "--json", scenario)
    assert status == 0, err
    report = json.loads(out)
    assert report["plugin_failures"] == []
    assert report["frames"] > 0 and report["actors"]
    for actor in report["actors"]:
        assert {"id", "character", "did"} <= set(actor)
        for b in actor.get("watching", {}).get("behaviours", []):
            assert b["known"] or b["path"] == []


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_save(scenario, tmp_path):
    target = tmp_path / "state.json"
    status, out, err = likeme("run", "--save", target, scenario)
    assert status == 0, err
    state = read_state(target)  # checked against its schema and checksum
    assert state


def test_learned_movement_of_a_posegraph_is_named_in_the_text_report():
    status, out, err = likeme("run", "learn_windmill")
    assert status == 0, err
    assert "learned learned-1" in out


def test_the_report_says_shrugs_only_when_the_observer_shrugged():
    # Max imitates what he recognises in learn_windmill: he does not shrug at the jump he cannot explain
    _, out, _ = likeme("run", "learn_windmill")
    line = next(x for x in out.splitlines() if "does not know why morris did jump" in x)
    assert "shrugs" not in line and "Max imitates it" in line
    # in ice_cream he does not imitate, and shrugs at the reach for an object he knows nothing of
    _, out, _ = likeme("run", "ice_cream")
    assert "Max does not know why morris did reach and shrugs" in out
    assert "did: shrug at" in out


def test_behaviour_sentence_without_a_response_names_no_response():
    b = {"known": False, "movement": "jump", "response": None}
    assert behaviour_sentence("Max", "morris", b) == "Max does not know why morris did jump"


@pytest.mark.parametrize("value, fallback, names", [
    (True, "learned-1", ["learned-1"]),
    (False, "learned-1", []),
    (["a:e1", "a:e2"], None, ["a:e1", "a:e2"]),
    (("e1",), None, ["e1"]),
    ("learned-2", None, ["learned-2"]),
    (None, "x", []),
])
def test_names_of_any_shape(value, fallback, names):
    assert _names(value, fallback) == names


def test_edges_accept_anything_a_matcher_reports():
    assert _edges(["arm:e1", "arm:e2"]) == "e1, e2"
    assert _edges(["arm:e1", "hand:e2"]) == "arm:e1, hand:e2"
    assert _edges(True) == "" and _edges("w") == "w"
