"""The forward models' predictions (:mod:`plugins.matchers.forward_model.prediction`): the candidates predicted and
extended at once are those predicted and extended one by one, to the last bit, so an answer (a drop-out at a
threshold, a commitment) can never differ."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import Track
from tests.plugins.matchers.forward_model.helpers import random_strokes

coordinates = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lengths=arrays(np.float64, 2, elements=st.floats(0.0, 1.0)),
       last=arrays(np.float64, (2, 3), elements=coordinates),
       first=arrays(np.float64, (2, 3), elements=coordinates), order=st.randoms(use_true_random=False))
def test_candidates_predicted_at_once_are_predicted_one_by_one(write, pm, lengths, last, first, order):
    """:meth:`Predictions.errors` (the one-command candidates stacked) gives each candidate exactly the error
    :meth:`Predictions.error` gives it alone, in the candidates' order, with anchors."""
    character, names = random_strokes(write, pm)
    predictions = character.matcher.predictions
    paths = [(name,) for name in names] + [(names[0], names[1])]
    order.shuffle(paths)
    track = Track("wrists", 1.0, False, "hub", 0, {p: 0.0 for p in paths}, sorted(names), first=first)
    got = predictions.errors(track, paths, lengths, last)
    assert list(got) == paths
    assert got == {path: predictions.error(track, path, lengths, last) for path in paths}


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lengths=arrays(np.float64, 2, elements=st.floats(0.0, 1.5)),
       first=arrays(np.float64, (2, 3), elements=st.floats(-1.0, 2.0)), seed=st.integers(0, 3),
       excluded=st.integers(0, 5))
def test_candidates_extended_at_once_are_extended_one_by_one(write, pm, lengths, first, seed, excluded):
    """:meth:`Predictions.extended_at_once` gives the paths, in order, that the path-by-path loop gives, whether
    a candidate has covered its command (and goes on along every edge of its end node but itself and the excluded)
    or not."""
    character, names = random_strokes(write, pm, strokes=5, seed=seed)
    matcher, motor = character.matcher, character.motor
    for i, name in enumerate(names[:3]):  # commands from the end nodes of the first ones, to go on along
        end = motor.edge(name).target
        rest = motor.state("wrists", end)
        motor.learn("wrists", end, [GuidingStroke(rest[0], rest[0] + 0.1 * (i + 1), 1.0),
                                    GuidingStroke(rest[1], rest[1], 1.0)])
    track = Track("wrists", 1.0, False, "hub", 0, {(name,): 0.0 for name in names}, sorted(names),
                  first=motor.rest[2:4] + first * 0.2, excluded=set(names[excluded:excluded + 1]))
    predictions, tables = matcher.predictions, matcher.tables
    want = []
    for path in track.candidates:  # the loop of extended, path by path
        lead = tables.lead(path[0])
        seen = matcher.anchors.along(track, path[0], lengths)[lead]
        total = sum(tables.edge(e).arcs[lead, -1] for e in path)
        want.extend(predictions.next(track, path) if seen > total + 0.01 / track.scale else [path])
    assert predictions.extended(track, lengths) == want
    assert predictions.extended_at_once(track, list(track.candidates), lengths) == want
