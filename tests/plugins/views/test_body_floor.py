"""The body view finds the floor a recording stands on: a Kinect body in camera coordinates (feet 1.1 m below the
origin) is drawn whole. Checked as numbers first (every point of every pose inside the picture's frame, each row
above the next), then as the picture ``likeme show`` writes."""

from __future__ import annotations

import numpy as np
import pytest

from likeme.cli import main
from tests.fixtures.schemes import KINECT_V2, KINECT_V2_PARTS
from tests.fixtures.skeletons import NAMES, human, performance, write_skeleton_csv

PROFILE = """
bones = [["root", "chest"], ["chest", "head"], ["chest", "left_shoulder"], ["left_shoulder", "left_wrist"],
         ["chest", "right_shoulder"], ["right_shoulder", "right_wrist"], ["root", "left_hip"],
         ["left_hip", "left_knee"], ["left_knee", "left_foot"], ["root", "right_hip"], ["right_hip", "right_knee"],
         ["right_knee", "right_foot"]]

[profile]
name = "kinect-camera"
units = "metre"
up = "+y"

[parts]
{parts}

[facing]
left = "left_hip"
right = "right_hip"
"""
# (no floor key: the user's profile says nothing of the camera; the view finds the floor)


def _camera(pose, floor=-1.1):
    """A body facing a depth camera (y up, z away from it), its feet ``-floor`` below the camera."""
    return pose * np.array([-1.0, 1.0, -1.0]) + np.array([0.0, floor, 2.5])


def test_the_floor_is_the_lowest_part_where_it_is_lowest():
    from plugins.views.body import floor_height, on_floor

    pose = _camera(performance(["bow", "wave"]))
    assert floor_height(pose) == pytest.approx(-1.1 + 0.02, abs=1e-6)  # the toes, 2 cm above the floor
    glitch = pose.copy()
    glitch[3, 5, 1] = -9.0  # one frame's foot tracked far below the floor
    glitch[4:8] = np.nan  # frames where nothing is seen
    assert floor_height(glitch) == pytest.approx(-1.08, abs=1e-6)
    assert floor_height(np.full((5, 3, 3), np.nan)) == 0.0
    seen = np.ones(pose.shape[:2], bool)
    legs = [NAMES.index(f"{side}_{j}") for side in "lr" for j in ("knee", "ankle", "toes")]
    seen[:, legs] = False  # the legs hidden: the lowest part seen is a hip or a hand
    assert floor_height(pose, seen) > -0.5
    assert np.nanmin(on_floor(pose)[..., 1]) == pytest.approx(0.0, abs=0.01)


@pytest.fixture
def kinect(tmp_path):
    (tmp_path / "kinect.toml").write_text(PROFILE.format(parts=KINECT_V2_PARTS))
    takes = [write_skeleton_csv(tmp_path / f"{m}.csv", KINECT_V2, _camera(human(m, 90)), up="+y")
             for m in ("bow", "wave")]
    return tmp_path / "kinect.toml", takes


def test_a_kinect_body_in_camera_coordinates_is_laid_out_whole(kinect):
    from plugins.lib.clip_repertoire import clip_repertoire
    from plugins.views.body import BodyView
    from plugins.views.demonstration import recording
    from toolkit import create_plugin_manager
    from toolkit.observe import compose_observer
    from toolkit.recordings.profile import load_profile

    path, takes = kinect
    profile = load_profile(path)
    demos = [recording(profile, t) for t in takes]
    assert np.nanmin(demos[0].motion.positions[..., 1]) < -1.0  # read as the camera gives it
    pm = create_plugin_manager(autoload=False, trace=False)
    character = compose_observer(pm, profile, clip_repertoire([d.motion for d in demos], ["bow", "wave"], profile),
                                 matcher="")
    view = BodyView(keys=3, width=400)
    sheet = view.layout(character, recordings=demos)
    points = sheet.poses[np.isfinite(sheet.poses).all(axis=-1)]
    (x0, y0), (x1, y1) = sheet.lower, sheet.upper
    assert (points[:, 0] >= x0).all() and (points[:, 0] <= x1).all()
    assert (points[:, 1] >= y0).all() and (points[:, 1] <= y1).all(), "a body cut off by the frame"
    hub, rows = sheet.poses[0], sheet.poses[1:].reshape(len(demos), 3, *sheet.poses.shape[1:])
    tops = [np.nanmax(r[..., 1]) for r in rows]
    bottoms = [np.nanmin(r[..., 1]) for r in rows]
    assert np.nanmin(hub[:, 1]) > tops[0] and bottoms[0] > tops[1], "rows overlap"
    for r in rows:  # each key pose stands on its row's line: the feet near its lowest point
        feet = r[:, [profile.body.index("left_foot"), profile.body.index("right_foot")], 1].min(axis=1)
        assert np.ptp(feet) < 0.05 and 1.3 < np.nanmax(r[..., 1]) - feet.min() < 1.7


def test_show_draws_the_kinect_recordings_whole(kinect, tmp_path, capsys):
    imageio = pytest.importorskip("imageio.v2")
    path, takes = kinect
    assert main(["show", "--body", str(path), *map(str, takes), "--view", "body", "--out", str(tmp_path),
                 "--set", "keys=3", "--set", "width=400"]) == 0
    out = tmp_path / "recordings-body.png"
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    image = imageio.imread(out)[..., :3].astype(int)
    drawn = (np.abs(image - 255).sum(axis=-1) > 30).any(axis=1)
    assert not drawn[0] and not drawn[-1], "a body touches the picture's edge"
    bands = int((np.diff(np.concatenate([[0], drawn.astype(int)])) == 1).sum())
    assert bands >= 1 + len(takes)  # the hub pose, then a row of poses per recording
