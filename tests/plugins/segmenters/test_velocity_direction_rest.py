"""velocity-direction's ``end = "rest"``: a movement ends where the demonstrator comes to rest where it began.

Kopp & Graeser 2006 (§4.1) end a movement wherever the sensory memory finds the parts at rest, so a gesture that
holds a pose half-way (a salute, a bow, a pointing hand) is two movements. ``end = "rest"`` ends it only at a rest
near the pose it began from (B&B's hub, the demonstrator's own), or after ``rest.settle`` seconds of rest elsewhere (a new
stance). The paper's rule stays the default.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.metrics import segmentation_scores
from plugins.lib.guiding_stroke import GuidingStroke
from plugins.segmenters.velocity_direction import VelocityDirection
from toolkit import Motion

FPS = 30.0
RELATIVE = {"units": "body", "noise": 2.0}  # the rest speed above this demonstrator's own noise (docs/correspondence.md)


def _stroke(a: np.ndarray, b: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return GuidingStroke(a, b, rng.uniform(0.4, 0.7), 0.5, 0.4, "linear", rng.normal(size=3), 0.0, 0.5,
                         0.0).trajectory(FPS)[:-1]


def movements_with_holds(rng: np.random.Generator, n_movements: int, hold_s: float, noise: float,
                         rest_s: float = 0.8) -> tuple[Motion, list[tuple[int, int]]]:
    """Movements that go out, hold a pose for ``hold_s`` seconds, and come back to the rest they left (a salute, a
    bow), separated by rests of ``rest_s`` seconds; the wrist's positions with tracker noise (m). The truth: the
    movements, from leaving the rest to being back."""
    home = np.array([0.0, 1.0, 0.3])
    rest, hold = int(round(rest_s * FPS)), int(round(hold_s * FPS))
    chunks, truth, at = [np.repeat([home], rest, 0)], [], rest
    for _ in range(n_movements):
        target = home + rng.uniform(-0.4, 0.4, 3)
        while np.linalg.norm(target - home) < 0.3:
            target = home + rng.uniform(-0.4, 0.4, 3)
        pieces = [_stroke(home, target, rng), np.repeat([target], hold, 0), _stroke(target, home, rng)]
        length = sum(len(p) for p in pieces)
        chunks += [*pieces, np.repeat([home], rest, 0)]
        truth.append((at, at + length))
        at += length + rest
    path = np.concatenate(chunks) + rng.normal(0.0, noise, (at, 3))
    return Motion(np.stack([np.zeros_like(path), path], 1), FPS, ("root", "wrist")), truth


def _scores(params: dict, motion: Motion, truth: list[tuple[int, int]]) -> dict:
    found = VelocityDirection(level="movement", **params).segment(motion)
    return segmentation_scores([(s.start, s.end) for s in found], truth)


@given(seed=st.integers(0, 10_000), hold=st.floats(0.3, 1.2))
@settings(max_examples=15, deadline=None)
def test_a_hold_away_from_rest_does_not_end_the_movement(seed, hold):
    """A hold of 0.3-1.2 s half-way (shorter than ``settle``) under 1 mm of noise: the paper's end (any rest)
    cuts every movement in two at its hold (one half counts for it, the other is a false movement: precision 0.5);
    ``end = "rest"`` finds each whole movement."""
    motion, truth = movements_with_holds(np.random.default_rng(seed), 3, hold, noise=0.001)
    assert _scores({"end": "rest"}, motion, truth)["f1"] == pytest.approx(1.0)
    paper = _scores({}, motion, truth)
    assert paper["found"] == 2 * len(truth) and paper["precision"] == pytest.approx(0.5)


def test_a_new_stance_ends_the_movement_after_settle():
    """A movement that does not come back (the demonstrator steps into a new stance and stays): it ends after
    ``settle`` seconds of rest there, where the rest began, and the next movement, from the new stance back to it,
    ends when it is back."""
    rng = np.random.default_rng(3)
    home, away, aside = np.array([0.0, 1.0, 0.3]), np.array([0.4, 1.0, 0.3]), np.array([0.4, 1.3, 0.3])
    rest = int(FPS)
    there = _stroke(home, away, rng)
    out, back = _stroke(away, aside, rng), _stroke(aside, away, rng)
    stay = int(3 * FPS)  # longer than settle (2 s)
    path = np.concatenate([np.repeat([home], rest, 0), there, np.repeat([away], stay, 0), out,
                           np.repeat([aside], int(0.5 * FPS), 0), back, np.repeat([away], rest, 0)])
    path = path + rng.normal(0.0, 0.001, path.shape)
    motion = Motion(np.stack([np.zeros_like(path), path], 1), FPS, ("root", "wrist"))
    arrived = rest + len(there)
    second = arrived + stay
    truth = [(rest, arrived), (second, second + len(out) + int(0.5 * FPS) + len(back))]
    found = VelocityDirection(level="movement", end="rest").segment(motion)
    assert len(found) == 2
    assert abs(found[0].end - arrived) <= 6  # where the rest began, not settle later
    assert segmentation_scores([(s.start, s.end) for s in found], truth)["f1"] == pytest.approx(1.0)
    never = VelocityDirection(level="movement", end="rest", rest={"settle": 60.0}).segment(motion)
    assert len(never) == 1  # without settle it never comes back to where it began: one movement to the end


def test_the_papers_end_is_the_default():
    """``end = "still"`` is the default, and any rest ends a movement there, whatever ``rest.radius`` and
    ``rest.settle`` say."""
    motion, _ = movements_with_holds(np.random.default_rng(5), 2, 0.6, noise=0.001)
    plain = VelocityDirection(level="movement")
    assert plain.params["end"] == "still"
    odd = VelocityDirection(level="movement", end="still", rest={"radius": 0.0, "settle": 0.0})
    assert plain.segment(motion) == odd.segment(motion)


def test_the_rest_radius_is_in_body_sizes():
    """The same movements on a body ten times as large (every position times ten) are cut at the same frames:
    the radius and the rest speed (``units = "body"``) are both measured in the demonstrator's own size."""
    motion, truth = movements_with_holds(np.random.default_rng(8), 3, 0.6, noise=0.001)
    large = Motion(motion.positions * 10.0, FPS, motion.parts)
    params = {"level": "movement", "end": "rest", "units": "body"}
    small_found = VelocityDirection(**params).segment(motion)
    assert [(s.start, s.end) for s in VelocityDirection(**params).segment(large)] == [
        (s.start, s.end) for s in small_found]
    assert segmentation_scores([(s.start, s.end) for s in small_found], truth)["f1"] == pytest.approx(1.0)


def test_end_rest_on_the_projects_generated_streams(tmp_path):
    """Morris's movements one after another from his rest pose (``likeme bench make-data``, 3 mm noise): several of
    them hold a pose half-way. With the rest speed above the noise, the paper's end cuts them at their holds;
    ``end = "rest"`` finds the movements (F1 at least 0.9, and above the paper's end)."""
    from plugins.bench.data import make_data
    from plugins.bench.mocap import segmentation
    from toolkit import create_plugin_manager
    from toolkit.recordings.profile import load_profile

    pm = create_plugin_manager()
    folder = make_data(pm, tmp_path / "gen", streams=2, per_stream=5)
    profile = load_profile(folder / "profile.toml")
    f1 = {}
    for end in ("still", "rest"):
        settings_ = {"segmenter": {"level": "movement", "end": end, **RELATIVE}}
        result = segmentation(pm, profile, folder / "streams", ["velocity-direction"], repertoire=folder / "repertoire",
                              settings=settings_)
        f1[end] = result["plugins"][0]["f1"]
    assert f1["rest"] >= 0.9 and f1["rest"] > f1["still"], f1
