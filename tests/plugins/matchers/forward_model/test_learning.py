"""True imitation (:mod:`plugins.matchers.forward_model.learning`; K&G §4.3): what no edge predicts is learned by the
inverse model as new edges from the node the subsystem was in, cut into strokes as the matcher's ``[strokes]`` table
says."""

from __future__ import annotations

import numpy as np

from tests.plugins.matchers.forward_model.helpers import demonstration, out_and_up, stroke_path
from toolkit.watching import feed


def test_a_movement_no_edge_predicts_is_learned_as_a_new_edge(arms):
    """Inwards and down, 135 degrees from both edges: both candidates drop on the same frame, nothing is committed,
    and the inverse model learns one stroke from the hub to a new node where the wrist stopped."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [-0.2, -0.2, 0.0]))
    assert all(a is None for a in feed(arms.matcher, demo))
    learned = arms.matcher.conclude(demo)
    assert learned.details["learned"] and learned.details["from"] == "hub" and not learned.details["deviated"]
    edge = arms.motor.edge(learned.details["learned"][-1])
    assert edge.target != "hub" and len(learned.details["learned"]) == 1
    np.testing.assert_allclose(edge.commands[0].target, arms.motor.rest[2] + [-0.2, -0.2, 0.0], atol=0.01)
    assert arms.motor.active_node("wrists") == edge.target


def _corner(arms):
    """Inwards, then down: two straight strokes at a right angle, the wrist pausing between them."""
    start = arms.motor.rest[2]
    first = stroke_path(start, [-0.2, 0.0, 0.0], duration=0.6)
    return demonstration(arms, np.concatenate([first, stroke_path(first[-1], [0.0, -0.2, 0.0], duration=0.6)[1:]]))


def test_the_strokes_table_cuts_what_is_learned(write, pm):
    """A corner (two strokes at a right angle) is learned as two edges with the stroke segmentation's defaults
    (``[matcher.strokes]``: a speed minimum below half its neighbours' peaks, or a turn of more than 50 degrees),
    and as one when neither criterion can cut it (no speed minimum counts, no turn is large enough)."""
    counts = {}
    for name, table in (("defaults", ""), ("uncut", "[matcher.strokes]\ndrop = 0.0\nangle = 180.0\n")):
        character = out_and_up(write, pm, table)
        demo = _corner(character)
        assert all(a is None for a in feed(character.matcher, demo))
        counts[name] = len(character.matcher.conclude(demo).details["learned"])
    assert counts == {"defaults": 2, "uncut": 1}

