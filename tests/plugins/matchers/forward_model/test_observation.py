"""The demonstration as the forward model reads it (:mod:`plugins.matchers.forward_model.observation`): the working
memory in the motor frame, each followed subsystem's rows and path lengths kept frame by frame, give every
candidate's error the direct formulas give on the whole segment seen so far, to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from plugins.matchers.forward_model.path_length import lengths
from tests.plugins.matchers.forward_model.helpers import FPS, random_strokes
from toolkit import Motion
from toolkit.watching import ObservationLog


def _direct_errors(matcher, observed: np.ndarray, root_height: np.ndarray, idx, paths, track) -> dict:
    """The prediction errors the direct formulas give after the frames ``observed`` (whole segment each time)."""
    local = observed + root_height
    seen = local[track.onset:, idx]
    return {path: matcher.predictions.error(track, path, lengths(seen), seen[-1]) for path in paths}


@pytest.mark.parametrize("hidden", [False, True])
def test_frame_by_frame_errors_are_the_whole_segments(write, pm, hidden):
    """Fed a demonstration frame by frame, every candidate's error in the trace is what the direct formulas give
    on the whole segment seen so far; with the head hidden for the first frames, too (its first sighting, while the
    wrists are followed, rewrites the rows before: working memory's revision, and what was kept is recomputed)."""
    character, names = random_strokes(write, pm, strokes=5, seed=3)
    matcher, motor = character.matcher, character.motor
    rest = motor.rest
    n = 40
    t = np.linspace(0.0, 1.0, n)[:, None]
    frames = np.repeat(rest[None], n, axis=0)
    frames[:, 2] = rest[2] + t * np.array([0.25, 0.1, -0.05]) + 0.002 * np.sin(40 * t)
    frames[:, 3] = rest[3] + t * np.array([0.0, 0.03, 0.0])
    visible = np.ones(frames.shape[:2], dtype=bool)
    if hidden:
        visible[:10, 1] = False
        frames[:10, 1] = np.nan
    motion = Motion(frames - rest[0], FPS, character.body.parts, visible)
    log = ObservationLog(motion.parts, FPS, capacity=1)
    memory = log.since(0)
    matcher.begin(memory)
    root_height = matcher.observation.root_height
    checked = 0
    for row in range(n):
        log.extend(motion.positions[row : row + 1], motion.visible[row : row + 1])
        memory.feed(row + 1)
        matcher.observe(memory)
        # the working memory it keeps in its motor frame is the one it would compute whole
        np.testing.assert_array_equal(matcher.observation.local(), memory.positions + root_height)
        track = matcher.tracks.get("wrists")
        if track is None or not track.trace or track.trace[-1][0] != row:
            continue
        frame, errors = track.trace[-1]
        idx = motor.subsystems["wrists"]
        direct = _direct_errors(matcher, memory.positions, root_height, idx, list(errors), track)
        assert list(errors) == list(direct)
        np.testing.assert_array_equal(list(errors.values()), list(direct.values()), err_msg=f"frame {frame}")
        checked += 1
    assert checked >= 10  # the candidates were followed for a while, across the head's first sighting
    assert (memory.revision > 0) == hidden
