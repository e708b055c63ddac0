"""Body profiles: a motion-capture skeleton read as a likeme body."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import BANDAI, CHARACTERS
from toolkit import ConfigError
from toolkit.bvh import from_joint_positions, read_bvh, write_bvh
from toolkit.profile import load_profile

PROFILE = """
[profile]
name = "max-cm"
units = "{units}"
up = "{up}"

[parts]
{parts}

[facing]
left = "left_knee"
right = "right_knee"
forward = "nose"
"""


def _max_parts(max_character):
    return "\n".join(f'{p} = "J_{p}"' for p in max_character.body.parts)


def _write_max_clip(max_character, path, movement="jump", *, scale=100.0, up="+y"):
    motion = max_character.motor.perform(movement, fps=30)
    positions = motion.positions * scale
    if up == "+z":  # a z-up source: likeme's (x, y, z) is stored as (x, -z, y)
        positions = np.stack([positions[..., 0], -positions[..., 2], positions[..., 1]], axis=-1)
    root = max_character.body.root_index
    parents = [-1 if i == root else root for i in range(len(motion.parts))]
    order = [root] + [i for i in range(len(motion.parts)) if i != root]
    names = [f"J_{motion.parts[i]}" for i in order]
    parents = [-1] + [0] * (len(order) - 1)
    write_bvh(from_joint_positions(names, parents, positions[:, order], 30.0), path)
    return motion


@pytest.mark.parametrize("units, scale, up", [("centimetre", 100.0, "+y"), ("mm", 1000.0, "+z"), ("m", 1.0, "+y")])
def test_a_profile_gives_metres_with_y_up_in_the_bodys_part_order(tmp_path, write, max_character, units, scale, up):
    clip = _write_max_clip(max_character, tmp_path / "jump.bvh", scale=scale, up=up)
    profile = load_profile(write("max.toml", PROFILE.format(units=units, up=up, parts=_max_parts(max_character))))
    motion = profile.read(tmp_path / "jump.bvh")
    assert motion.parts == max_character.body.parts
    np.testing.assert_allclose(motion.positions, clip.positions, atol=1e-5)
    assert profile.body.facing.forward == "nose"


def test_unmapped_joints_are_listed_and_a_missing_joint_is_named(tmp_path, write, max_character):
    _write_max_clip(max_character, tmp_path / "jump.bvh")
    parts = _max_parts(max_character).replace('nose = "J_nose"\n', "")
    profile = load_profile(write("few.toml", PROFILE.format(units="cm", up="+y", parts=parts).replace(
        'forward = "nose"', 'forward = "head"')))
    assert profile.check(read_bvh(tmp_path / "jump.bvh")) == ["J_nose"]
    broken = load_profile(write("typo.toml", PROFILE.format(units="cm", up="+y", parts=_max_parts(max_character))
                                .replace('"J_head"', '"J_heda"')))
    with pytest.raises(ConfigError) as info:
        broken.read(tmp_path / "jump.bvh")
    message = str(info.value)
    assert "typo.toml:" in message and "key parts.head" in message and "'J_heda'" in message
    assert "available: J_root, J_head" in message


@pytest.mark.parametrize(
    "edit, expected",
    [
        (lambda t: t.replace('units = "cm"', 'units = "furlong"'), "key profile.units: unknown units 'furlong'"),
        (lambda t: t.replace('units = "cm"', "units = -2"), "expected a unit name or a positive number"),
        (lambda t: t.replace('up = "+y"', 'up = "sky"'), "key profile.up: unknown up axis 'sky'; expected an axis; "
                                                       "available: +y, -y, +z, -z, +x, -x"),
        (lambda t: t.replace('left = "left_knee"', 'left = "left_kne"'), "key facing.left: unknown body part 'left_kne'"),
        (lambda t: t.replace("[facing]", "[facings]"), "unknown table 'facings'"),
        (lambda t: t.replace('name = "max-cm"', 'name = "max-cm"\nsize = 3'), "key profile.size: unknown key 'size'"),
        (lambda t: t.replace('root = "J_root"', 'root = 3'), "key parts.root: invalid joint 3"),
        (lambda t: t.replace('root = "J_root"\n', ''), "key parts: no part named 'root'"),
    ],
)
def test_a_malformed_profile_names_the_file_key_and_line(write, max_character, edit, expected):
    text = PROFILE.format(units="cm", up="+y", parts=_max_parts(max_character))
    path = write("bad.toml", edit(text))
    with pytest.raises(ConfigError) as info:
        load_profile(path)
    message = str(info.value)
    assert message.startswith(f"{path}:"), message
    assert expected in message


def test_the_shipped_bandai_namco_profile_loads():
    profile = load_profile(CHARACTERS / "profiles" / "bandai-namco.toml")
    assert profile.scale == 0.01 and profile.body.root == "root" and profile.joints[0] == "Hips"
    assert profile.body.facing.behind == "left_toes"


@pytest.mark.skipif(not BANDAI.is_dir(), reason=f"Bandai-Namco motion capture not found at {BANDAI}")
def test_the_facing_of_every_bandai_namco_clip_is_steady():
    from plugins.lib.root_frame import facing_heading

    profile = load_profile(CHARACTERS / "profiles" / "bandai-namco.toml")
    flips = frames = 0
    for path in sorted(BANDAI.glob("*.bvh")):
        motion = profile.read(path)
        heading = facing_heading(motion.positions, motion.visible, profile.body)
        flips += int((np.abs(np.angle(np.exp(1j * np.diff(heading)))) > 2).sum())
        frames += motion.n_frames
    assert flips / frames < 1e-3


def test_validate_checks_a_profile_and_bvh_files_against_it(tmp_path, write, max_character, capsys):
    from toolkit.cli import main

    _write_max_clip(max_character, tmp_path / "jump.bvh")
    profile = write("max.toml", PROFILE.format(units="cm", up="+y", parts=_max_parts(max_character)))
    assert main(["validate", str(profile)]) == 0
    assert main(["validate", "--body", str(profile), str(tmp_path / "jump.bvh")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith(f"body profile 'max-cm': {len(max_character.body.parts)} parts, units 0.01 m, up +y")
    n = len(max_character.body.parts)
    assert f"BVH: {n} joints" in out[1] and f"maps {n}, leaves 0 unmapped" in out[1]
