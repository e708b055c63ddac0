"""The takes' strokes as a second evidence beside a motion comparison (plugins.matchers.strokes_evidence): each
evidence weighed by how well the repertoire's takes show it separates the movements, the strokes only where they
separate them where the calibrated decision draws its line, pinned to the formula on hand-written scores. Path
search's use of it is tested in ``path_search/test_evidence.py``, the forward model's in
``forward_model/test_answer.py``."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.decision import Calibration
from plugins.matchers.strokes_evidence import MOST_SEPARATION, evidence_weights

RATE = 0.05
"""``known_rejected``, the template's."""


def _rows(own: float, other: float, takes: int = 2, movements: int = 2) -> tuple[np.ndarray, list[str]]:
    """Scores of ``takes`` takes of each of ``movements`` movements against each other: ``own`` between two takes
    of one movement, ``other`` between movements, ``inf`` on the diagonal."""
    labels = [f"m{i}" for i in range(movements) for _ in range(takes)]
    same = np.equal.outer(labels, labels)
    rows = np.where(same, own, other).astype(float)
    np.fill_diagonal(rows, np.inf)
    return rows, labels


def test_each_evidence_weighs_its_separation_over_its_spacing():
    """Motion: own 0.5, other 0.6; strokes: own 0.1, other 0.8: weights in the ratio log(1.2) / 0.6 to
    log(8) / 0.8, summing to 1."""
    motion, labels = _rows(0.5, 0.6)
    strokes, _ = _rows(0.1, 0.8)
    expected = np.array([np.log(1.2) / 0.6, np.log(8.0) / 0.8])
    assert evidence_weights([motion, strokes], labels, RATE) == pytest.approx(expected / expected.sum())


@pytest.mark.parametrize(("own", "other", "expected"), [
    (0.9, 0.6, [1.0, 0.0]),     # the strokes' takes lie as far apart as movements: they weigh nothing
    (0.0, 0.8, None),           # two copies of one clip: the most separation counts, not an infinite one
])
def test_an_evidence_that_separates_nothing_weighs_nothing_and_copies_do_not_weigh_everything(own, other, expected):
    motion, labels = _rows(0.3, 0.6)
    strokes, _ = _rows(own, other)
    weights = evidence_weights([motion, strokes], labels, RATE)
    if expected is None:
        expected = np.array([np.log(2.0) / 0.6, MOST_SEPARATION / 0.8])
        expected = expected / expected.sum()
    assert weights == pytest.approx(expected)


@pytest.mark.parametrize("case", ["one take of each", "one movement", "nothing separates"])
def test_where_the_takes_show_no_separation_the_motion_decides_alone(case):
    rows = {"one take of each": _rows(0.2, 0.6, takes=1), "one movement": _rows(0.2, 0.6, movements=1),
            "nothing separates": _rows(0.7, 0.6)}[case]
    assert evidence_weights([rows[0], rows[0]], rows[1], RATE).tolist() == [1.0, 0.0]


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from("abc"), min_size=1, max_size=7).flatmap(lambda labels: st.tuples(
    st.just(labels), arrays(np.float64, (len(labels), len(labels)), elements=st.floats(0.0, 2.0)))))
def test_the_calibration_of_rows_is_each_takes_nearest_own_and_other(case):
    """Each take's row, itself left out: own is the least of its movement's other takes, other the least of every
    other movement's takes; takes with neither give nothing."""
    labels, rows = case
    rows = rows.copy()
    np.fill_diagonal(rows, 5.0)  # never read
    got = Calibration.of_rows(rows, labels)
    own = [min(rows[c, d] for d in range(len(labels)) if d != c and labels[d] == labels[c]) for c in range(len(labels))
           if labels.count(labels[c]) > 1]
    other = [min(rows[c, d] for d in range(len(labels)) if labels[d] != labels[c]) for c in range(len(labels))
             if len(set(labels)) > 1]
    assert got == Calibration.of(own, other)


def test_the_strokes_count_only_where_they_separate_the_movements_where_the_decision_reads_them():
    """Strokes whose takes lie far nearer each other than movements on the whole (own 0.1, other 0.8), but one of
    ten movements' takes as far apart as movements come (0.9): at the quantiles the decision reads
    (``known_rejected``) they separate nothing and weigh nothing; read at the medians (0.5) they weigh most."""
    motion, labels = _rows(0.3, 0.6, movements=10)
    strokes, _ = _rows(0.1, 0.8, movements=10)
    strokes[0, 1] = strokes[1, 0] = 0.9
    assert evidence_weights([motion, strokes], labels, RATE).tolist() == [1.0, 0.0]
    assert evidence_weights([motion, strokes], labels, 0.5)[1] > 0.5


def test_the_matchers_own_comparison_counts_by_its_medians_even_where_its_tails_overlap():
    """Takes of two performers: the motion's own takes lie as far apart at the tails as movements (one pair at 0.9),
    and nearer on the whole (0.3 against 0.6); the strokes separate at the tails too. The motion, the matcher's own
    comparison, still weighs its median separation: the strokes do not decide alone."""
    motion, labels = _rows(0.3, 0.6, movements=10)
    motion[0, 1] = motion[1, 0] = 0.9
    strokes, _ = _rows(0.1, 0.8, movements=10)
    expected = np.array([np.log(2.0) / 0.6, np.log(8.0) / 0.8])
    assert evidence_weights([motion, strokes], labels, RATE) == pytest.approx(expected / expected.sum())
