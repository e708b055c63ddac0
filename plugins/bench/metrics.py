"""Scores of segmentation and recognition, as the benchmarks report them.

- A found segment *counts* for a true movement when its midpoint lies inside the
  true movement and it overlaps that movement by at least half of its own
  length; counting is one to one (each true movement is claimed at most once,
  by the found segment that overlaps it most).
- Boundaries: each pair's start and end, compared with the true movement's, give the *boundary error* (mean
  absolute difference in frames over the pairs' boundaries) and the share of the true boundaries (two a true
  movement) that a found segment puts within a tolerance (``likeme bench segmentation``: 0.25 s) of where they
  are; a true movement no segment counts for has both its boundaries missed, so the share falls with recall too.
- The movement error rate is the edit distance (insertions, deletions,
  substitutions) between the recognised and the true label sequences, divided by
  the number of true movements (``rapidfuzz``'s Levenshtein distance).
- Recognition: the macro F1 over the true labels and the confusion matrix
  (``scikit-learn``'s ``f1_score`` and ``confusion_matrix``).

The segment matching rule is this project's own (the benchmarks' definition of a found
movement), so it stays written out here.
"""

from __future__ import annotations

import warnings
from collections.abc import Hashable, Sequence

import numpy as np

__all__ = ["match_segments", "segmentation_scores", "edit_distance", "movement_error_rate", "macro_f1",
           "confusion_matrix"]

Span = tuple[int, int]


def match_segments(found: Sequence[Span], truth: Sequence[Span]) -> list[tuple[int, int]]:
    """One-to-one pairs (found index, true index) under the midpoint-and-half-overlap rule."""
    candidates = []
    for i, (fs, fe) in enumerate(found):
        mid = 0.5 * (fs + fe)
        for j, (ts, te) in enumerate(truth):
            overlap = min(fe, te) - max(fs, ts)
            if ts <= mid < te and overlap >= 0.5 * (fe - fs):
                candidates.append((overlap, i, j))
    pairs, used_f, used_t = [], set(), set()
    for overlap, i, j in sorted(candidates, key=lambda c: -c[0]):
        if i not in used_f and j not in used_t:
            pairs.append((i, j))
            used_f.add(i)
            used_t.add(j)
    return sorted(pairs)


def segmentation_scores(found: Sequence[Span], truth: Sequence[Span], tolerance: float = 0.0) -> dict[str, float]:
    """Precision, recall, F1 and the boundary scores of found against true segments.

    ``boundary_error``: mean absolute difference (frames) between the paired segments' starts and ends (NaN without
    a pair); ``boundary_errors``: each of those differences (two a pair); ``within``: the share of the true
    boundaries (two a true movement) a paired segment puts no farther than ``tolerance`` frames away (1.0 without
    true movements).
    """
    pairs = match_segments(found, truth)
    tp = len(pairs)
    precision = tp / len(found) if found else (1.0 if not truth else 0.0)
    recall = tp / len(truth) if truth else 1.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    errors = [abs(found[i][0] - truth[j][0]) for i, j in pairs] + [abs(found[i][1] - truth[j][1]) for i, j in pairs]
    return {
        "precision": precision,
        "recall": recall,
        "f1": f1,
        "true_positives": tp,
        "found": len(found),
        "true": len(truth),
        "boundary_error": float(np.mean(errors)) if errors else float("nan"),
        "boundary_errors": [float(e) for e in errors],
        "within": sum(e <= tolerance for e in errors) / (2 * len(truth)) if truth else 1.0,
    }


def edit_distance(a: Sequence[Hashable], b: Sequence[Hashable]) -> int:
    """Levenshtein distance between two label sequences (insertions, deletions and substitutions cost 1)."""
    from rapidfuzz.distance import Levenshtein

    ids: dict[Hashable, int] = {}  # labels as integers: rapidfuzz compares other objects by their hash
    return int(Levenshtein.distance([ids.setdefault(x, len(ids)) for x in a], [ids.setdefault(y, len(ids)) for y in b]))


def movement_error_rate(recognised: Sequence[str], truth: Sequence[str]) -> float:
    """Edit distance between recognised and true sequences over the number of true movements."""
    return edit_distance(recognised, truth) / max(len(truth), 1)


def macro_f1(truth: Sequence[str], predicted: Sequence[str]) -> float:
    """The mean over the true labels of each label's F1 (2 tp / (2 tp + fp + fn)); 0 without items.

    A label only predicted (``unknown`` for a known movement, say) costs its true label a miss and counts no F1
    of its own."""
    if not len(truth):
        return 0.0
    from sklearn.metrics import f1_score

    return float(f1_score(list(truth), list(predicted), labels=sorted(set(truth)), average="macro", zero_division=0.0))


def confusion_matrix(truth: Sequence[str], predicted: Sequence[str], labels: Sequence[str]) -> np.ndarray:
    """Counts (len(labels), len(labels)): row the true label, column the predicted one."""
    if not len(labels):
        return np.zeros((0, 0), dtype=int)
    from sklearn.metrics import confusion_matrix as counts

    with warnings.catch_warnings():  # one label: the matrix is 1 x 1, as asked (its warning is for labels not given)
        warnings.filterwarnings("ignore", "A single label was found", UserWarning)
        return counts(list(truth), list(predicted), labels=list(labels)).astype(int)
