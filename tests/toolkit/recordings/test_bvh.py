"""BVH reading, writing and forward kinematics."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.conftest import BANDAI
from toolkit import ConfigError
from toolkit.recordings.bvh import BVH, Joint, parse_bvh, read_bvh
from toolkit.recordings.bvh_writer import format_bvh, from_joint_positions, write_bvh
SMALL = """HIERARCHY\r
ROOT hips\r
{\r
\tOFFSET 0 0 0\r
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\r
\tJOINT chest\r
\t{\r
\t\tOFFSET 0 1.0E+1 0\r
\t\tCHANNELS 3 Xrotation Yrotation Zrotation\r
\t\tJOINT arm\r
\t\t{\r
\t\t\tOFFSET 5 0 0\r
\t\t\tCHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation\r
\t\t\tEnd Site\r
\t\t\t{\r
\t\t\t\tOFFSET 2.5e0 0 0\r
\t\t\t}\r
\t\t}\r
\t}\r
}\r
MOTION\r
Frames: 2\r
Frame Time: 0.0333333\r
0 90 0 0 0 0  0 0 0  5 0 0 0 0 0\r
1 90 0 90 0 0  0 0 0  5 0 0 0 0 0\r
"""


def test_a_small_file_with_crlf_tabs_mixed_orders_and_an_end_site():
    bvh = parse_bvh(SMALL, "small.bvh")
    assert bvh.names == ["hips", "chest", "arm", "arm_end"]
    assert bvh.joints[3].end_site and bvh.joints[3].parent == 2
    assert bvh.n_frames == 2 and bvh.fps == pytest.approx(30.0, rel=1e-4)
    p = bvh.positions()
    np.testing.assert_allclose(p[0], [[0, 90, 0], [0, 100, 0], [5, 100, 0], [7.5, 100, 0]], atol=1e-9)
    # frame 1: the root turns 90 degrees about +z (first channel of the intrinsic ZXY order): x becomes y
    np.testing.assert_allclose(p[1, 1], [1 - 10, 90, 0], atol=1e-9)
    np.testing.assert_allclose(p[1, 3], [1 - 10, 90 + 7.5, 0], atol=1e-9)


def test_position_channels_replace_the_offset_on_any_joint():
    text = SMALL.replace("5 0 0 0 0 0\r\n1 90", "9 0 0 0 0 0\r\n1 90")
    p = parse_bvh(text).positions()
    np.testing.assert_allclose(p[0, 2], [9, 100, 0], atol=1e-9)  # the arm's OFFSET 5 is replaced by its channel 9


def test_rotation_channels_compose_intrinsically_in_file_order():
    joints = [Joint("a", -1, (0, 0, 0), ("Yrotation", "Xrotation", "Zrotation")), Joint("a_end", 0, (1, 2, 3), (), True)]
    angles = np.array([[30.0, -40.0, 75.0]])
    p = BVH(joints, 0.1, angles).positions()
    expected = Rotation.from_euler("YXZ", angles, degrees=True).apply([1, 2, 3])
    np.testing.assert_allclose(p[0, 1], expected[0], atol=1e-9)


@st.composite
def bvh_files(draw):
    n = draw(st.integers(1, 6))
    frames = draw(st.integers(1, 5))
    joints = []
    for j in range(n):
        parent = -1 if j == 0 else draw(st.integers(0, j - 1))
        rotation = draw(st.permutations(["Xrotation", "Yrotation", "Zrotation"]))
        with_position = j == 0 or draw(st.booleans())
        channels = (["Xposition", "Yposition", "Zposition"] if with_position else []) + list(rotation)
        offset = tuple(draw(st.floats(-100, 100, allow_nan=False)) for _ in range(3))
        joints.append(Joint(f"j{j}", parent, offset, tuple(channels)))
    ends = draw(st.lists(st.integers(0, n - 1), max_size=2, unique=True))
    for e in ends:
        joints.append(Joint(f"j{e}_end", e, (0.0, 5.0, 1e-5), (), True))
    # a writer emits children after their parent: order the list as a depth-first walk would
    order, stack = [], [0]
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed([k for k, jt in enumerate(joints) if jt.parent == i]))
    remap = {old: new for new, old in enumerate(order)}
    joints = [Joint(joints[i].name, remap.get(joints[i].parent, -1), joints[i].offset, joints[i].channels,
                    joints[i].end_site) for i in order]
    count = sum(len(j.channels) for j in joints)
    values = np.array(draw(st.lists(st.floats(-180, 180, allow_nan=False), min_size=frames * count,
                                    max_size=frames * count))).reshape(frames, count)
    return BVH(joints, draw(st.sampled_from([1 / 30, 1 / 120, 0.01])), values, "generated")


@settings(max_examples=60, deadline=None)
@given(bvh_files())
def test_write_then_read_gives_the_same_motion(bvh):
    back = parse_bvh(format_bvh(bvh, precision=12), "again.bvh")
    assert back.names == bvh.names
    assert [j.channels for j in back.joints] == [j.channels for j in bvh.joints]
    assert back.frame_time == pytest.approx(bvh.frame_time, rel=1e-8)
    np.testing.assert_allclose(back.values, bvh.values, rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(back.positions(), bvh.positions(), atol=1e-6)


def test_a_motion_written_by_likeme_reads_back_to_the_same_positions(tmp_path, max_character):
    motion = max_character.motor.perform("jump", fps=30)
    parents = [-1 if p == "root" else max_character.body.parts.index("root") for p in motion.parts]
    bvh = from_joint_positions(motion.parts, parents, motion.positions * 100, motion.fps)
    path = write_bvh(bvh, tmp_path / "jump.bvh")
    back = read_bvh(path)
    assert back.names == list(motion.parts)
    np.testing.assert_allclose(back.positions() / 100, motion.positions, atol=1e-6)
    assert back.fps == pytest.approx(30.0)
    assert not list(tmp_path.glob("*.tmp"))


@pytest.mark.parametrize(
    "edit, where, expected",
    [
        (lambda t: t.replace("HIERARCHY", "HIERARCHIE"), ":1:1:", "expected 'HIERARCHY'"),
        (lambda t: t.replace("OFFSET 5 0 0", "OFFSET 5 zero 0"), ":12:13:", "expected an OFFSET coordinate"),
        (lambda t: t.replace("CHANNELS 3 Xrotation", "CHANNELS 3 Xrot"), ":9:14:", "expected a channel name"),
        (lambda t: t.replace("Frames: 2", "Frames: 3"), ":26:1:", "expected 3 frame lines"),
        (lambda t: t.replace("1 90 0 90 0 0  0 0 0  5 0 0 0 0 0", "1 90 0 90 0 0  0 0 0  5 0 0 0 0"), ":25:1:",
         "frame 2 has 14 values; expected 15 channel values"),
        (lambda t: t.replace("1 90 0 90", "1 90 0 nan"), ":25:", "expected a finite channel value"),
        (lambda t: t.replace("1 90 0 90", "1 90 0 x9"), ":25:", "expected a number"),
        (lambda t: t.replace("Frame Time: 0.0333333", "Frame Time: 0"), ":23:13:", "expected a positive number"),
        (lambda t: t.split("MOTION")[0], ":21:1:", "expected 'MOTION'"),
        (lambda t: t.replace("\t\t\t}\r\n\t\t}", "\t\t\t}\r\n\t\tOFFSET"), ":18:3:", "expected 'JOINT', 'End Site' or '}'"),
    ],
)
def test_a_malformed_file_names_the_line_and_column_and_what_was_expected(edit, where, expected):
    with pytest.raises(ConfigError) as info:
        parse_bvh(edit(SMALL), "bad.bvh")
    message = str(info.value)
    assert message.startswith("bad.bvh" + where), message
    assert expected in message


def test_a_missing_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match="nothere.bvh: cannot read"):
        read_bvh(tmp_path / "nothere.bvh")


@pytest.mark.skipif(not BANDAI.is_dir(), reason=f"Bandai-Namco motion capture not found at {BANDAI}")
def test_a_bandai_namco_clip():
    bvh = read_bvh(BANDAI / "dataset-1_bow_normal_001.bvh")
    assert bvh.fps == pytest.approx(30.0, rel=1e-4) and bvh.n_frames == 138
    assert "Toes_L_end" in bvh.names and all(len(j.channels) == 6 for j in bvh.joints if not j.end_site)
    p = bvh.positions()
    head, foot = p[0, bvh.index("Head")], p[0, bvh.index("Toes_L")]
    assert 130 < head[1] - foot[1] < 170  # a standing adult, in centimetres, +y up


def test_a_joint_list_not_in_depth_first_order_is_written_with_its_values_under_their_joints():
    """Joints listed root, left hip, right hip, left knee (not depth first: the hierarchy names the left knee before
    the right hip): each joint's channel values are written in the column its place in the hierarchy gives, so the
    file read back has every joint's own values."""
    from toolkit.recordings.bvh import BVH, Joint, parse_bvh
    from toolkit.recordings.bvh_writer import format_bvh

    rot = ("Zrotation", "Xrotation", "Yrotation")
    joints = [Joint("root", -1, (0.0, 1.0, 0.0), ("Xposition", "Yposition", "Zposition", *rot)),
              Joint("left_hip", 0, (0.1, 0.0, 0.0), rot), Joint("right_hip", 0, (-0.1, 0.0, 0.0), rot),
              Joint("left_knee", 1, (0.0, -0.4, 0.0), rot), Joint("left_foot", 3, (0.0, -0.4, 0.0), (), True)]
    values = np.arange(2 * 15, dtype=float).reshape(2, 15)  # every column its own number
    back = parse_bvh(format_bvh(BVH(joints, 1 / 30, values)))
    names = [j.name for j in back.joints if not j.end_site]
    assert names == ["root", "left_hip", "left_knee", "right_hip"]
    columns = {"root": values[:, 0:6], "left_hip": values[:, 6:9], "right_hip": values[:, 9:12],
               "left_knee": values[:, 12:15]}
    at = 0
    for joint in back.joints:
        if joint.end_site:
            continue
        width = len(joint.channels)
        assert np.array_equal(back.values[:, at : at + width], columns[joint.name]), joint.name
        at += width
