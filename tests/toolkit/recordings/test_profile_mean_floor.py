"""A part that is the mean of joints (MediaPipe's pelvis), and a floor below the origin (a camera's frame)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from tests.fixtures.schemes import MEDIAPIPE
from tests.fixtures.skeletons import NAMES, human, write_skeleton_csv
from toolkit import ConfigError
from toolkit.recordings.profile import load_profile

PROFILE = """
[profile]
name = "mediapipe"
up = "-y"
floor = {floor}

[parts]
root = {{mean = ["left_hip", "right_hip"]}}
head = "nose"
left_hip = "left_hip"
right_hip = "right_hip"
left_foot = "left_ankle"
right_foot = "right_ankle"

[facing]
left = "left_hip"
right = "right_hip"
forward = "head"
"""


def test_a_mean_part_is_the_mean_of_its_joints_and_seen_when_all_are(tmp_path, write):
    pose = human("bow")
    path = write_skeleton_csv(tmp_path / "pose.csv", MEDIAPIPE, pose, up="-y")
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    row = lines[5].split(",")
    row[header.index("right_hip_x")] = "nan"  # the right hip not seen in frame 4
    lines[5] = ",".join(row)
    path.write_text("\n".join(lines) + "\n")
    profile = load_profile(write("mp.toml", PROFILE.format(floor=0.0)))
    motion = profile.read(path)
    root = motion.positions[:, 0]
    expected = (pose[:, NAMES.index("l_hip")] + pose[:, NAMES.index("r_hip")]) / 2
    seen = np.ones(len(pose), bool)
    seen[4] = False
    np.testing.assert_allclose(root[seen], expected[seen], atol=1e-5)
    assert not motion.visible[4, 0] and motion.visible[4, 1] and motion.visible[seen, 0].all()
    assert profile.npy_joints == ("left_hip", "right_hip", "nose", "left_ankle", "right_ankle")


def test_the_floor_is_subtracted_from_every_height(tmp_path, write):
    pose = human("wave") + np.array([0.0, -1.1, 2.5])  # a camera's frame: feet 1.1 m below the origin
    path = write_skeleton_csv(tmp_path / "cam.csv", MEDIAPIPE, pose, up="-y")
    lifted = load_profile(write("mp.toml", PROFILE.format(floor=-1.1))).read(path)
    raw = load_profile(write("raw.toml", PROFILE.format(floor=0.0))).read(path)
    np.testing.assert_allclose(lifted.positions, raw.positions + [0.0, 1.1, 0.0], atol=1e-9)
    assert abs(lifted.positions[:, 4, 1].min() - 0.08) < 1e-3  # the ankle 8 cm above the floor, as generated


@pytest.mark.parametrize("parts, expected", [
    ('root = {mean = ["left_hip"]}', "a mean of two or more joints"),
    ('root = {mean = ["left_hip", "left_hip"]}', "a mean of two or more joints"),
    ('root = {middle = ["left_hip", "right_hip"]}', "invalid joint"),
    ('root = [{mean = ["a", "b"]}, {mean = ["a", "b"]}]', "joint names repeated"),
])
def test_a_bad_mean_is_named(write, parts, expected):
    text = PROFILE.format(floor=0).replace('root = {mean = ["left_hip", "right_hip"]}', parts)
    with pytest.raises(ConfigError) as info:
        load_profile(write("bad.toml", text))
    assert "key parts.root" in str(info.value) and expected in str(info.value)


@pytest.mark.parametrize("floor", ['"low"', "true", "nan", "1e9"])
def test_a_bad_floor_is_named(write, floor):
    with pytest.raises(ConfigError, match="key profile.floor: invalid floor"):
        load_profile(write("bad.toml", PROFILE.format(floor=floor)))


def test_a_mean_part_missing_a_joint_names_the_mean(tmp_path, write):
    path = write_skeleton_csv(tmp_path / "pose.csv", MEDIAPIPE[:5], human("rest"))  # no right side
    with pytest.raises(ConfigError, match="the mean of 'left_hip', 'right_hip' of part 'root' is not in"):
        load_profile(write("mp.toml", PROFILE.format(floor=0))).read(path)


def test_a_live_input_refuses_a_mean_part_by_name(tmp_path, write):
    from toolkit.recordings.live import LiveInput

    path = write_skeleton_csv(tmp_path / "pose.csv", MEDIAPIPE, human("rest"))
    with pytest.raises(ConfigError, match="part 'root' is the mean of 'left_hip', 'right_hip': a live input"):
        LiveInput(io.BytesIO(path.read_bytes()), load_profile(write("mp.toml", PROFILE.format(floor=0))))
