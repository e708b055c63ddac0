"""Max the learner (Kopp & Graeser 2006) watching with his eye: an arm hides the hand behind it (hidden_hand_games)."""

from __future__ import annotations

import pytest

from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_scenario

SCENE = CHARACTERS / "scenarios" / "hidden_hand_games.toml"


def _learned(world):
    """(time, learned edge names) of each demonstration Max learned from."""
    return [(round(e.time, 2), list(e.data["match"].details.get("learned", [])))
            for e in world.events_of("movement_recognised", "max") if e.data["match"].details.get("learned")]


@pytest.fixture(scope="module")
def seen():
    return load_scenario(SCENE, create_plugin_manager(autoload=False)).run()


def test_the_arm_across_hides_the_left_hand_while_it_closes(seen):
    max_ = seen.actors["max"]
    assert max_.character.perception.name == "rendered-vision"
    memory = max_.memory
    wrist, fist = memory.parts.index("left_wrist"), memory.parts.index("left_index")
    behind = slice(int(1.4 * 30), int(2.0 * 30))  # the fist held behind the arm (fist_behind_arm, from 0.53 s)
    hidden = ~memory.visible[behind.start + 16 : behind.stop + 16, wrist]
    assert hidden.mean() > 0.9 and (~memory.visible[behind.start + 16 : behind.stop + 16, fist]).mean() > 0.9
    assert memory.visible[: 10, wrist].all()  # seen before the arm came across


def test_max_learns_the_arm_he_saw_and_not_the_fist_he_did_not(seen):
    """The first demonstration teaches the right wrist's strokes (across and back) and nothing of the left hand; the
    second, in plain sight, teaches the fist."""
    learned = _learned(seen)
    first = [names for t, names in learned if t < 4.9]
    second = [names for t, names in learned if t >= 4.9]
    assert first and all(name.startswith("right_wrist:") for names in first for name in names)
    assert not any(name.startswith("left_hand:") for names in first for name in names)
    assert second and any(name.startswith("left_hand:") for names in second for name in names)
    graphs = seen.actors["max"].character.motor.graphs
    assert graphs["right_wrist"].number_of_edges() == 2 and graphs["left_hand"].number_of_edges() == 2


def test_through_motion_capture_he_learns_the_fist_the_first_time(write):
    """The same games watched through motion capture (max_learner.toml's perception): nothing is hidden, the fist is
    learned in the first demonstration and recognised in the second."""
    text = SCENE.read_text().replace('"../', f'"{CHARACTERS}/')
    text = text[: text.index("[actors.override.perception]")]
    world = load_scenario(write("mocap.toml", text), create_plugin_manager(autoload=False)).run()
    assert world.actors["max"].character.perception.name == "motion-capture"
    learned = _learned(world)
    first = [name for t, names in learned if t < 4.9 for name in names]
    assert any(name.startswith("left_hand:") for name in first)
    assert not any(name.startswith("left_hand:") for t, names in learned if t >= 4.9 for name in names)
    recognised = [e.data["match"] for e in world.events_of("movement_recognised", "max") if e.time >= 4.9]
    assert any(m.movement and "left_hand:" in m.movement for m in recognised)
