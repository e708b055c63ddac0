"""Scenario tests for the papers' worked examples that no other test file replays (the table: docs/examples.md)."""

from __future__ import annotations

from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_scenario


def test_learn_windmill_learned_then_recognised():
    """Buchsbaum & Blumberg 2005, §5.2.3 and §7.3: Morris swings his arms like a windmill, a movement Max does not
    have; Max adds the observed path to his posegraph as a new movement and imitates it; after a jump he knows, the
    second windmill is recognised as the movement he learned, and nothing more is learned."""
    scenario = load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", create_plugin_manager(autoload=False))
    world = scenario.world
    max_ = world.actors["max"]
    before = set(max_.character.motor.movements())
    assert "windmill" not in before
    scenario.run()
    assert [r.movement for _, r in world.actors["morris"].performed] == ["windmill", "jump", "windmill"]
    matches = [e.data["match"] for e in world.events_of("movement_recognised", "max")]
    assert [m.movement for m in matches] == ["learned-1", "jump", "learned-1"]
    assert matches[0].details.get("learned") and not matches[2].details.get("learned")
    assert set(max_.character.motor.movements()) - before == {"learned-1"}  # one new movement, learned once
    assert [(r.movement, r.imitating) for _, r in max_.performed] == [
        ("learned-1", "morris"), ("jump", "morris"), ("learned-1", "morris")]
