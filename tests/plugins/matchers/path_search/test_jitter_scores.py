"""Path search's scores depend far less on how noisy the tracker was once its jitter is taken out
(plugins.lib.jitter, plugins.matchers.tempo): the same hand gestures recorded clean and with a Kinect's jitter
(likeme bench make-gestures) score nearer alike, and recorded clean exactly as before."""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.gestures import make_gestures
from toolkit import create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """The same performances (one seed) recorded clean and with 1.5 cm of jitter, 3 cm at the hands."""
    root = tmp_path_factory.mktemp("jitter-scores")
    return {name: make_gestures(root / name, seed=5, performers=2, takes=2, jitter=jitter, lost=0.0)
            for name, jitter in (("clean", 0.0), ("noisy", 0.015))}


def _scores(folder, comparison: str = "motion") -> np.ndarray:
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(folder / "profile.toml")
    observer = compose_observer(pm, profile, folder / "repertoire", matcher="path-search",
                                settings={"matcher": {"comparison": comparison}})
    scores = []
    for clip in sorted(folder.glob("demos/*/*_p2_001.csv")):
        if any(f"_{style}_" in clip.name for style in ("normal", "big", "slow")):
            motion = profile.read(clip)
            match = Observer(observer, profile.body, motion.fps).classify(motion).match
            scores.append(match.score)
    return np.array(scores)


def test_a_noisy_tracker_scores_the_same_performances_nearly_as_a_clean_one(recorded, monkeypatch):
    import plugins.matchers.tempo as tempo

    clean, noisy = _scores(recorded["clean"]), _scores(recorded["noisy"])
    assert len(clean) == 18
    monkeypatch.setattr(tempo, "less_jitter", lambda found, moving, *args: (found, moving))
    left_in, clean_left_in = _scores(recorded["noisy"]), _scores(recorded["clean"])
    # the jitter left in raises every score far; taken out, less than half as much remains (about a third)
    assert np.median(left_in - clean) > 0.2
    assert np.median(noisy - clean) < 0.5 * np.median(left_in - clean)
    # recorded clean, nothing to take out
    assert clean == pytest.approx(clean_left_in, abs=0.01)
