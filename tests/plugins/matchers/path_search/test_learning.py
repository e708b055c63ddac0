"""Path search learns what it does not recognise as a new movement (Buchsbaum & Blumberg 2005, §5.2.3), under a
name no movement of the character has (plugins.lib.learned_names), whatever was learned or forgotten before."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from plugins.lib.learned_names import learned_name
from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_character


@given(st.sets(st.integers(1, 12)), st.sets(st.sampled_from(["wave", "learned", "learned-0", "learned-x", "x-1"])))
def test_a_learned_name_is_the_first_number_no_movement_has(numbers, others):
    known = {f"learned-{n}" for n in numbers} | others
    name = learned_name(known)
    assert name not in known
    free = int(name.rsplit("-", 1)[1])
    assert all(f"learned-{n}" in known for n in range(1, free))


def test_a_movement_learned_earlier_is_never_overwritten(tmp_path):
    """Max has kept ``learned-2`` (``learned-1`` forgotten); Morris's windmill, which Max does not know, is learned
    as ``learned-1``, the next unknown as ``learned-3``; ``learned-2`` is performed as it was."""
    pm = create_plugin_manager(autoload=False)
    learner = tmp_path / "learner.toml"
    learner.write_text(f'[character]\nname = "Learner"\nextends = "{CHARACTERS / "max.toml"}"\n'
                       '[matcher]\nlearn = true\n', encoding="utf-8")
    max_ = load_character(learner, pm)
    morris = load_character(CHARACTERS / "morris.toml", pm)
    kept = morris.motor.perform("jump", fps=30).root_relative("root")
    max_.motor.learn("learned-2", kept.positions, kept.visible)
    before = max_.motor.perform("learned-2", fps=30).positions
    windmill = morris.motor.perform("windmill", fps=30).root_relative("root")
    first = max_.matcher.match(windmill)
    assert first.movement == "learned-1" and first.details["learned"]
    assert np.array_equal(max_.motor.perform("learned-2", fps=30).positions, before)
    mirrored = windmill.positions * np.array([-1.0, 1.0, -1.0])  # the windmill turned round: a movement of its own
    turned = type(windmill)(np.ascontiguousarray(mirrored[::-1]), windmill.fps, windmill.parts)
    second = max_.matcher.match(turned)
    assert second.movement in ("learned-1", "learned-3")
    assert {"learned-1", "learned-2"} <= set(max_.motor.movements())
    assert np.array_equal(max_.motor.perform("learned-2", fps=30).positions, before)
