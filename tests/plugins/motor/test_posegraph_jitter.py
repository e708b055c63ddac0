"""The jitter a posegraph's nodes keep from their clips (Posegraph.node_noise, plugins.lib.jitter): what a tracker's
noise leaves after the clips' low-pass, none from a clean recording, none from key poses."""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.gestures import make_gestures
from plugins.lib.jitter import feature_noise
from toolkit import create_plugin_manager, load_character
from toolkit.config.search import resolve_file
from toolkit.observe import compose_observer
from toolkit.recordings.profile import load_profile


def _motor(folder):
    pm = create_plugin_manager(autoload=False, trace=False)
    return compose_observer(pm, load_profile(folder / "profile.toml"), folder / "repertoire",
                            matcher="path-search").motor


@pytest.mark.parametrize("jitter", [0.005, 0.01])
def test_a_trackers_clips_leave_their_low_passed_jitter_in_the_nodes(tmp_path, jitter):
    motor = _motor(make_gestures(tmp_path, seed=2, performers=1, takes=2, jitter=jitter, lost=0.0))
    interior = np.flatnonzero(motor.node_noise[:, 0] > 0)
    assert len(interior) > 0.8 * (len(motor.node_noise) - len(motor.hubs))
    # each part about the root: its own jitter and the root's; of the 19 parts, 14 have the jitter, the 4 wrists and
    # hands twice it, and the root none of its own about itself
    per_axis = jitter**2 * (14 * (1 + 1) + 4 * (4 + 1) + 0) / 19
    expected = feature_noise(np.array([per_axis]), 30.0, 120, low_passed=True)[0]
    assert np.median(motor.node_noise[interior], axis=0) == pytest.approx(expected, rel=0.1)


def test_clean_clips_and_key_poses_leave_none(tmp_path):
    clean = _motor(make_gestures(tmp_path, seed=2, performers=1, takes=2, jitter=0.0, lost=0.0))
    assert np.sqrt(clean.node_noise[:, 0]).max() < 0.002  # a millimetre or so: the movements' own curvature
    pm = create_plugin_manager(autoload=False, trace=False)
    max_character = load_character(resolve_file("max.toml", None, pm), pm)
    assert not max_character.motor.node_noise.any()
