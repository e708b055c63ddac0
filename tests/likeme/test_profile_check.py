"""Profiles that check themselves: `likeme validate --body` warnings and `likeme profile` proposals (issue 20)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from likeme.profiles import SCHEMES, propose_profile, recording_warnings
from tests.conftest import BANDAI, CHARACTERS
from tests.fixtures.skeletons import BANDAI as BANDAI_SKELETON
from tests.fixtures.skeletons import KINECT, human, performance, write_skeleton_bvh, write_skeleton_csv
from toolkit import ConfigError
from toolkit.recordings.bvh import parse_bvh
from likeme.cli import main
from toolkit.recordings.positions import read_positions
from toolkit.recordings.profile import load_profile


def run(capsys, *args):
    """The likeme command in-process: (exit status, stdout, stderr lines)."""
    status = main([str(a) for a in args])
    out = capsys.readouterr()
    return status, out.out, out.err.splitlines()


def warnings_of(lines):
    return [line for line in lines if line.startswith("likeme: warning: ")]


@pytest.fixture
def bandai_like(tmp_path):
    """A recording with the Bandai-Namco skeleton's joints, hierarchy and zero-offset end sites, in centimetres."""
    return write_skeleton_bvh(tmp_path / "take.bvh", BANDAI_SKELETON, performance(["wave", "bow", "wave"]),
                              scale=100.0)


def proposed(tmp_path, capsys, recording, name="proposed.toml"):
    status, out, err = run(capsys, "profile", recording, "--out", tmp_path / name)
    assert status == 0, err
    assert warnings_of(err) == [], err
    return tmp_path / name


# -- duplicate joint names: an end site never replaces another joint silently ------------------------------------

END_SITE_BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 3 Xposition Yposition Zposition
  JOINT Head
  {
    OFFSET 0 1 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 0.2 0
    }
  }
  JOINT Head_end
  {
    OFFSET 0 1 0
    CHANNELS 3 Zrotation Xrotation Yrotation
  }
}
MOTION
Frames: 1
Frame Time: 0.033333
0 0 0 0 0 0 0 0 0
"""


def test_a_joint_named_like_an_earlier_end_site_is_an_error_naming_both():
    with pytest.raises(ConfigError) as info:
        parse_bvh(END_SITE_BVH, "dup.bvh")
    message = str(info.value)
    assert message.startswith("dup.bvh:15:9: duplicate joint name 'Head_end'"), message
    assert "the end site of joint 'Head' at line 10" in message


def test_an_end_site_named_like_an_earlier_joint_is_an_error_naming_both():
    head = END_SITE_BVH[END_SITE_BVH.index("  JOINT Head\n"):END_SITE_BVH.index("  JOINT Head_end")]
    other = END_SITE_BVH[END_SITE_BVH.index("  JOINT Head_end"):END_SITE_BVH.index("}\nMOTION")]
    with pytest.raises(ConfigError) as info:
        parse_bvh(END_SITE_BVH.replace(head + other, other + head), "dup.bvh")
    message = str(info.value)
    assert "the end site of joint 'Head' is named 'Head_end', like the joint at line 6" in message
    assert "dup.bvh:15:5" in message


def test_end_sites_with_their_own_names_still_read():
    bvh = parse_bvh(END_SITE_BVH.replace("JOINT Head_end", "JOINT Jaw"))
    assert bvh.names == ["Hips", "Head", "Head_end", "Jaw"]


def test_two_parts_mapping_one_joint_are_a_warning(tmp_path, capsys, bandai_like):
    profile = proposed(tmp_path, capsys, bandai_like)
    text = profile.read_text().replace('neck = "Neck"', 'neck = "Chest"')
    profile.write_text(text)
    status, _, err = run(capsys, "validate", "--body", profile, bandai_like)
    assert status == 0
    assert warnings_of(err) == [f"likeme: warning: {profile}: parts 'chest' and 'neck' both map joint 'Chest': they "
                                "are one point"]
    assert run(capsys, "validate", "--strict", profile)[2][-1] == warnings_of(err)[0]  # the profile alone too


# -- warnings of validate --body ---------------------------------------------------------------------------------


@pytest.mark.parametrize("units, height", [("metre", "158 m tall"), ("millimetre", "0.158 m tall"),
                                           ("inch", "4.01 m tall")])
def test_validate_warns_for_a_profile_with_the_wrong_units(tmp_path, capsys, bandai_like, units, height):
    profile = proposed(tmp_path, capsys, bandai_like)
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(re.sub(r'units = "centimetre".*', f'units = "{units}"', profile.read_text()))
    status, out, err = run(capsys, "validate", "--body", wrong, bandai_like)
    assert status == 0 and out.startswith("ok    ")
    (line,) = warnings_of(err)
    assert line.startswith(f"likeme: warning: {bandai_like}: the body is {height}")
    assert "a body standing upright is 0.3 to 3 m tall: the units are probably wrong" in line
    assert line.endswith('(units = "centimetre" would make it 1.58 m)')
    assert run(capsys, "validate", "--strict", "--body", wrong, bandai_like)[0] == 1
    assert run(capsys, "validate", "--strict", "--body", profile, bandai_like)[0] == 0


@pytest.mark.parametrize("up, why", [("-y", "the root is below the feet in 100% of the frames and the head is under "
                                            "the hips in 100% of the frames"),
                                     ("+z", "the root is below the feet in 100% of the frames"),
                                     ("-x", "the head-above-feet direction is 90 degrees from up")])
def test_validate_warns_for_a_profile_with_the_wrong_up_axis(tmp_path, capsys, bandai_like, up, why):
    profile = proposed(tmp_path, capsys, bandai_like)
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(re.sub(r'up = "\+y".*', f'up = "{up}"', profile.read_text()))
    status, _, err = run(capsys, "validate", "--body", wrong, bandai_like)
    assert status == 0
    (line,) = warnings_of(err)
    assert line == (f'likeme: warning: {bandai_like}: up = "{up}" is probably wrong: {why}; the file\'s up axis '
                    'looks like "+y"')


def test_validate_names_the_frames_where_the_facing_flips(tmp_path, capsys):
    clip = write_skeleton_bvh(tmp_path / "swing.bvh", BANDAI_SKELETON, human("rest", 240, swing=True), scale=100.0)
    profile = proposed(tmp_path, capsys, clip)  # the proposal's facing (the hips and the shoulders) stays steady
    text = profile.read_text()
    assert 'left = ["left_hip", "left_shoulder"]' in text and 'right = ["right_hip", "right_shoulder"]' in text
    wrong = tmp_path / "wrong.toml"  # the left hand swings in front of the body and behind it: a bad forward marker
    assert "\nforward =" not in text
    wrong.write_text(text + 'forward = "left_wrist"\n')
    status, _, err = run(capsys, "validate", "--body", wrong, clip)
    assert status == 0
    (line,) = warnings_of(err)
    frames = [int(f) for f in re.search(r"1000: frames ([\d, ]+);", line).group(1).split(", ")]
    assert "the facing flips (turns by more than 115 degrees in a frame) in 8 of 240 frames" in line
    swing = np.sin(2 * np.pi * 4 * np.linspace(0.0, 1.0, 240))  # the hand crosses the hips' line where it changes sign
    crossings = np.flatnonzero(np.diff(np.sign(swing + 0.02 / 0.35)) != 0) + 1
    assert all(min(abs(f - crossings)) <= 2 for f in frames), (frames, crossings)


def test_a_facing_that_flips_rarely_is_no_warning(tmp_path, capsys, bandai_like):
    """One flip in 1000 frames is allowed (the Bandai-Namco clips have 4 in 30,000)."""
    from likeme.profiles import RecordingCheck

    profile = load_profile(proposed(tmp_path, capsys, bandai_like))
    motion = profile.read(bandai_like)
    check = RecordingCheck(profile)
    positions = np.concatenate([motion.positions] * 6)  # 1560 frames, with one flip made by hand
    positions[700:] = positions[700:] * np.array([-1.0, 1.0, -1.0])  # half a turn about +y at frame 700
    check.update(positions, np.ones(positions.shape[:2], bool))
    assert check.warnings() == []
    check.update(positions[:1000], np.ones((1000, positions.shape[1]), bool))  # 2560 frames, 3 flips: > 1/1000
    (line,) = check.warnings()
    assert "in 3 of 2560 frames" in line and "frames 700, 1560, 2260;" in line


# -- likeme profile ----------------------------------------------------------------------------------------------


def test_profile_proposes_a_working_profile_for_a_bandai_namco_skeleton(tmp_path, capsys, bandai_like):
    profile = load_profile(proposed(tmp_path, capsys, bandai_like))
    shipped = load_profile(CHARACTERS / "profiles" / "bandai-namco.toml")
    assert (profile.scale, profile.up) == (0.01, "+y")
    assert dict(zip(profile.body.parts, profile.joints)) == dict(zip(shipped.body.parts, shipped.joints))
    assert set(profile.body.bones) == set(shipped.body.bones)
    assert (profile.body.facing.left, profile.body.facing.right) == ("left_hip", "right_hip")
    assert (profile.body.facing.forward, profile.body.facing.behind) == (None, None)  # the hips say it all
    status, out, err = run(capsys, "validate", "--body", profile.file, bandai_like)
    assert status == 0 and err == [], err
    # and likeme observe watches the recording with it (a repertoire of the same skeleton)
    for movement in ("wave", "bow"):
        (tmp_path / "rep" / movement).mkdir(parents=True)
        write_skeleton_bvh(tmp_path / "rep" / movement / "clip.bvh", BANDAI_SKELETON, human(movement, turn=0.0),
                           scale=100.0)
    status, out, err = run(capsys, "observe", "--body", profile.file, "--repertoire", tmp_path / "rep", bandai_like)
    assert status == 0, err
    assert re.findall(r"\)  (\w+) ", out) == ["wave", "bow", "wave"], out


@pytest.fixture
def kinect_repertoire(tmp_path):
    for movement in ("wave", "bow"):
        (tmp_path / "rep" / movement).mkdir(parents=True)
        write_skeleton_bvh(tmp_path / "rep" / movement / "clip.bvh", KINECT, human(movement, turn=0.0))
    return tmp_path / "rep"


def test_profile_proposes_a_working_profile_for_a_kinect_skeleton(tmp_path, capsys, kinect_repertoire):
    take = write_skeleton_bvh(tmp_path / "kinect.bvh", KINECT, performance(["bow", "wave"]))
    path = proposed(tmp_path, capsys, take)
    profile = load_profile(path)
    parts = dict(zip(profile.body.parts, profile.joints))
    assert (profile.scale, profile.up, parts["root"]) == (1.0, "+y", "SpineBase")
    assert {parts[p] for p in ("left_shoulder", "left_elbow", "left_wrist", "left_hip", "left_knee", "left_foot")} == \
        {"ShoulderLeft", "ElbowLeft", "WristLeft", "HipLeft", "KneeLeft", "AnkleLeft"}
    assert ("left_knee", "left_foot") in profile.body.bones and ("chest", "right_shoulder") in profile.body.bones
    assert "# joints not mapped: SpineMid" in path.read_text()
    status, _, err = run(capsys, "validate", "--body", path, take)
    assert status == 0 and err == [], err
    status, out, err = run(capsys, "observe", "--body", path, "--repertoire", kinect_repertoire, take)
    assert status == 0, err
    assert re.findall(r"\)  (\w+) ", out) == ["bow", "wave"], out


def test_profile_reads_a_kinect_csv_in_millimetres_with_z_up(tmp_path, capsys):
    take = write_skeleton_csv(tmp_path / "kinect.csv", KINECT, performance(["bow", "wave"]), scale=1000.0, up="+z")
    path = proposed(tmp_path, capsys, take)
    profile = load_profile(path)
    assert (profile.scale, profile.up) == (0.001, "+z")
    assert "the head is above the feet along the file's +z axis" in path.read_text()
    recording = read_positions(take)
    positions = profile.convert(recording.positions, list(recording.names))
    assert recording_warnings(profile, [(positions, np.isfinite(positions).all(axis=-1))]) == []
    head = positions[:, profile.body.index("head"), 1]
    assert 1.5 < np.median(head) < 1.7  # metres, +y up: the head where the generated body has it


def test_a_csv_without_a_time_column_gets_a_todo_for_its_frame_rate(tmp_path, capsys):
    take = write_skeleton_csv(tmp_path / "kinect.csv", KINECT, performance(["bow"]))
    lines = take.read_text().splitlines()
    take.write_text("\n".join(",".join(line.split(",")[1:]) for line in lines) + "\n")  # drop the time column
    status, out, err = run(capsys, "profile", take)
    assert status == 0 and warnings_of(err) == []
    assert "# TODO: the file gives no frame rate" in out


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(units=st.sampled_from([("metre", 1.0), ("centimetre", 100.0), ("millimetre", 1000.0)]),
       up=st.sampled_from(["+y", "+z", "-y"]), turn=st.floats(-3.0, 3.0), movement=st.sampled_from(["bow", "wave"]))
def test_the_proposed_units_and_up_axis_are_the_files(tmp_path, units, up, turn, movement):
    from tests.fixtures.skeletons import _skeleton_positions, source_axes

    names, parents, positions = _skeleton_positions(KINECT, human(movement, 90, turn=turn))
    proposal = propose_profile(names, source_axes(positions * units[1], up), parents=parents)
    assert f'units = "{units[0]}"' in proposal.text and f'up = "{up}"' in proposal.text
    assert proposal.todo == []


def _keypoints(tmp_path, scheme_names):
    """A CSV of a generated person with other keypoint names (the generated points they stand for)."""
    from tests.fixtures.skeletons import NAMES

    pose = performance(["wave"])
    header, cols = [], []
    for name, point in scheme_names:
        header += [f"{name}_{a}" for a in "xyz"]
        cols.append(pose[:, NAMES.index(point)])
    data = np.concatenate(cols, axis=1)
    path = tmp_path / "keypoints.csv"
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(f"{v:.5f}" for v in row) for row in data) + "\n")
    return path


def test_profile_maps_coco_and_mediapipe_keypoints_with_the_root_between_the_hips(tmp_path, capsys):
    coco = [("nose", "head"), ("left_shoulder", "l_shoulder"), ("right_shoulder", "r_shoulder"),
            ("left_elbow", "l_elbow"), ("right_elbow", "r_elbow"), ("left_wrist", "l_wrist"),
            ("right_wrist", "r_wrist"),
            ("left_hip", "l_hip"), ("right_hip", "r_hip"), ("left_knee", "l_knee"), ("right_knee", "r_knee"),
            ("left_ankle", "l_ankle"), ("right_ankle", "r_ankle")]
    for names in (coco, [(n.upper(), p) for n, p in coco]):  # COCO's names, MediaPipe's
        status, out, err = run(capsys, "profile", _keypoints(tmp_path, names))
        assert status == 0
        assert "MediaPipe/COCO keypoints scheme" in out and "TODO: no pelvis" not in out
        assert re.search(r'root = \{mean = \["(left_hip|LEFT_HIP)", "(right_hip|RIGHT_HIP)"\]\}', out)
        (tmp_path / "p.toml").write_text(out)
        profile = load_profile(tmp_path / "p.toml")
        parts = dict(zip(profile.body.parts, profile.joints))
        assert parts["left_foot"].lower() == "left_ankle" and parts["left_hip"].lower() == "left_hip"
        assert [j.lower() for j in parts["chest"]] == ["left_shoulder", "right_shoulder"]
        assert (profile.body.facing.left, profile.body.facing.right, profile.body.facing.forward) == \
            ("left_hip", "right_hip", "nose")


@pytest.mark.parametrize("prefix, names", [
    ("mixamorig:", {"root": "Hips", "chest": "Spine2", "left_shoulder": "LeftArm", "left_knee": "LeftLeg"}),
    ("", {"root": "Hips", "chest": "Spine1", "left_shoulder": "LeftArm", "left_knee": "LeftLeg"}),
])
def test_profile_maps_mixamo_and_cmu_names(prefix, names):
    joints = ["Hips", "Spine", "Spine1", "Spine2" if prefix else "LowerBack", "Neck", "Head", "LeftShoulder",
              "LeftArm", "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
              "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"]
    points = {"Hips": "hips", "Spine": "spine", "Spine1": "chest", "Spine2": "chest", "LowerBack": "spine",
              "Neck": "neck", "Head": "head", "Shoulder": "clavicle", "Arm": "shoulder", "ForeArm": "elbow",
              "Hand": "wrist", "UpLeg": "hip", "Leg": "knee", "Foot": "ankle", "ToeBase": "toes"}
    from tests.fixtures.skeletons import NAMES

    pose = human("wave")
    cols = []
    for j in joints:
        side = "l_" if j.startswith("Left") else "r_" if j.startswith("Right") else ""
        cols.append(pose[:, NAMES.index(side + points[j.removeprefix("Left").removeprefix("Right")])])
    proposal = propose_profile([prefix + j for j in joints], np.stack(cols, axis=1))
    assert proposal.scheme == ("Mixamo" if prefix else "CMU (cgspeed, MotionBuilder names)")
    for part, joint in names.items():
        assert f'{part} = "{prefix}{joint}"' in proposal.text


def test_a_skeleton_of_no_known_scheme_gets_todos_and_still_loads(tmp_path, capsys):
    names = [("pelvis_c", "hips"), ("skull", "head"), ("L_Knee", "l_knee"), ("R_Knee", "r_knee"),
             ("L_Heel", "l_ankle"), ("R_Heel", "r_ankle")]
    status, out, err = run(capsys, "profile", _keypoints(tmp_path, names))
    assert status == 0
    assert "joint names of no known scheme" in out and "TODO" in out
    assert any("no known joint-naming scheme" in line for line in err)
    (tmp_path / "p.toml").write_text(out)
    profile = load_profile(tmp_path / "p.toml")
    assert (profile.body.facing.left, profile.body.facing.right) == ("l_knee", "r_knee")
    assert profile.up == "+y" and profile.scale == 1.0


def test_every_scheme_names_a_root_or_its_proposal_says_so():
    """Every scheme's table maps its parts to joints; a scheme without a pelvis still gets a root (a TODO)."""
    for name, scheme in SCHEMES.items():
        assert scheme.name == name and "root" in scheme.parts, name
        assert all(isinstance(j, tuple) and j for j in scheme.parts.values()), name


@pytest.mark.skipif(not BANDAI.is_dir(), reason=f"Bandai-Namco motion capture not found at {BANDAI}")
def test_the_proposal_for_a_real_bandai_namco_clip_is_the_shipped_profile(tmp_path, capsys):
    clip = sorted(BANDAI.glob("*.bvh"))[0]
    profile = load_profile(proposed(tmp_path, capsys, clip))
    shipped = load_profile(CHARACTERS / "profiles" / "bandai-namco.toml")
    assert (profile.scale, profile.up) == (shipped.scale, shipped.up)
    assert dict(zip(profile.body.parts, profile.joints)) == dict(zip(shipped.body.parts, shipped.joints))
    assert (profile.body.facing.left, profile.body.facing.right) == (shipped.body.facing.left,
                                                                     shipped.body.facing.right)
    status, _, err = run(capsys, "validate", "--body", profile.file, *sorted(BANDAI.glob("*.bvh")))  # every clip
    assert status == 0 and warnings_of(err) == [], err


def test_a_joint_never_seen_and_gaps_leave_the_facing_to_a_pair_that_is_seen(tmp_path):
    """A Kinect CSV whose left hip is never tracked and whose every 7th frame is empty: the shoulders give the facing."""
    import warnings

    take = write_skeleton_csv(tmp_path / "kinect.csv", KINECT, performance(["bow"]), scale=1000.0, up="+z")
    lines = take.read_text().splitlines()
    header = lines[0].split(",")
    rows = [lines[0]]
    for i, line in enumerate(lines[1:]):
        values = line.split(",")
        rows.append(",".join("" if h.startswith("HipLeft") or (i % 7 == 0 and h != "time") else v
                             for h, v in zip(header, values)))
    take.write_text("\n".join(rows) + "\n")
    recording = read_positions(take)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning from a slice that is all NaN
        proposal = propose_profile(recording.names, recording.positions, source=take.name, fps=recording.fps)
    (tmp_path / "p.toml").write_text(proposal.text)
    profile = load_profile(tmp_path / "p.toml")
    assert (profile.scale, profile.up) == (0.001, "+z")
    assert (profile.body.facing.left, profile.body.facing.right) == ("left_shoulder", "right_shoulder")
    positions = profile.convert(recording.positions, list(recording.names))
    assert recording_warnings(profile, [(positions, np.isfinite(positions).all(axis=-1))]) == []
