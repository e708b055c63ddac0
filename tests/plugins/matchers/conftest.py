"""The matchers' shared fixture: ``gestures``, generated hand gestures with two takes of each movement."""

from __future__ import annotations

import pytest

from plugins.bench.gestures import make_gestures
from toolkit.recordings.profile import load_profile


@pytest.fixture(scope="session")
def gestures(tmp_path_factory):
    """(folder, profile, demos): the six gestures (waves and raises of the left, right and both hands), two takes of
    each by one performer as the repertoire; the demos another performer and six other styles of the first, as
    (movement, motion)."""
    folder = make_gestures(tmp_path_factory.mktemp("gestures"), seed=5, performers=2, takes=2)
    profile = load_profile(folder / "profile.toml")
    demos = [(clip.parent.name, profile.read(clip)) for clip in sorted((folder / "demos").glob("*/*.csv"))]
    return folder, profile, demos
