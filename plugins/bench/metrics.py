"""Scores of segmentation and recognition, as the benchmarks report them.

- A found segment *counts* for a true movement when its midpoint lies inside the
  true movement and it overlaps that movement by at least half of its own
  length; counting is one to one (each true movement is claimed at most once,
  by the found segment that overlaps it most).
- The movement error rate is the edit distance (insertions, deletions,
  substitutions) between the recognised and the true label sequences, divided by
  the number of true movements.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["match_segments", "segmentation_scores", "edit_distance", "movement_error_rate"]

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


def segmentation_scores(found: Sequence[Span], truth: Sequence[Span]) -> dict[str, float]:
    """Precision, recall, F1 and mean absolute boundary error (frames) of found against true segments."""
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
    }


def edit_distance(a: Sequence[str], b: Sequence[str]) -> int:
    """Levenshtein distance between two label sequences."""
    prev = np.arange(len(b) + 1)
    for i, x in enumerate(a, 1):
        cur = np.empty_like(prev)
        cur[0] = i
        for j, y in enumerate(b, 1):
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (x != y))
        prev = cur
    return int(prev[-1])


def movement_error_rate(recognised: Sequence[str], truth: Sequence[str]) -> float:
    """Edit distance between recognised and true sequences over the number of true movements."""
    return edit_distance(recognised, truth) / max(len(truth), 1)
