"""``likeme validate --body`` runs the same units, up and facing checks on every format (BVH, CSV, .npy, C3D), from
the motion the profile's stream gives; ``--strict`` fails a CSV with wrong units, a wrong up or a flipping facing as
it does a BVH file."""

from __future__ import annotations

import re

import numpy as np
import pytest

from likeme.cli import main
from plugins.bench.data import write_positions
from tests.fixtures.skeletons import BANDAI, _skeleton_positions, human, performance


def _run(capsys, *args):
    status = main([str(a) for a in args])
    out = capsys.readouterr()
    return status, out.out, [line for line in out.err.splitlines() if line.startswith("likeme: warning: ")]


@pytest.fixture
def takes(tmp_path, capsys):
    """The same take (Bandai-Namco's joints, centimetres, +y up) as BVH, CSV (with and without a header), .npy and
    C3D, and a profile proposed for the BVH file (with the ``joints`` list of the array and headerless CSV)."""
    from tests.fixtures.skeletons import write_skeleton_bvh

    pose = performance(["wave", "bow", "wave"])
    bvh = write_skeleton_bvh(tmp_path / "take.bvh", BANDAI, pose, scale=100.0)
    names, _, positions = _skeleton_positions(BANDAI, pose)  # end sites too: the joints a BVH reader gives
    positions = positions * 100.0
    files = {"bvh": bvh, "csv": write_positions(tmp_path / "take.csv", names, positions, fps=30.0),
             "npy": write_positions(tmp_path / "take.npy", names, positions),
             "c3d": write_positions(tmp_path / "take.c3d", names, positions, fps=30.0)}
    headerless = tmp_path / "headerless.csv"
    headerless.write_text("".join(files["csv"].read_text().splitlines(keepends=True)[1:]))
    files["headerless"] = headerless
    assert main(["profile", str(bvh), "--out", str(tmp_path / "p.toml")]) == 0
    capsys.readouterr()
    text = (tmp_path / "p.toml").read_text()
    joints = "joints = [" + ", ".join(f'"{n}"' for n in names) + "]"
    (tmp_path / "p.toml").write_text(text.replace("[profile]\n", f"[profile]\nfps = 30\n{joints}\n", 1))
    return tmp_path / "p.toml", files


FORMATS = ["bvh", "csv", "npy", "c3d", "headerless"]


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_right_profile_passes_strict_in_every_format(takes, capsys, fmt):
    profile, files = takes
    status, out, warnings = _run(capsys, "validate", "--strict", "--body", profile, files[fmt])
    assert status == 0 and out.startswith("ok    ") and warnings == []


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("edit, expected", [
    ((r'units = "centimetre".*', 'units = "metre"'), "the body is 158 m tall with units metre"),
    ((r'units = "centimetre".*', 'units = "inch"'), "the units are probably wrong"),
    ((r'up = "\+y".*', 'up = "-y"'), 'up = "-y" is probably wrong: the root is below the feet'),
    ((r'up = "\+y".*', 'up = "+z"'), 'up = "+z" is probably wrong'),
])
def test_strict_fails_wrong_units_and_a_wrong_up_in_every_format(takes, capsys, tmp_path, fmt, edit, expected):
    profile, files = takes
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(re.sub(*edit, profile.read_text()))
    status, _, warnings = _run(capsys, "validate", "--body", wrong, files[fmt])
    assert status == 0 and len(warnings) == 1 and expected in warnings[0]
    assert warnings[0].startswith(f"likeme: warning: {files[fmt]}: ")
    assert _run(capsys, "validate", "--strict", "--body", wrong, files[fmt])[0] == 1


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".c3d"])
def test_strict_fails_a_facing_that_flips_in_a_csv_as_in_a_bvh(tmp_path, capsys, suffix):
    """The left hand swings in front of the body and behind it: a forward marker that flips the facing."""
    from tests.fixtures.skeletons import write_skeleton_bvh

    pose = human("rest", 240, swing=True)
    bvh = write_skeleton_bvh(tmp_path / "swing.bvh", BANDAI, pose, scale=100.0)
    names, _, positions = _skeleton_positions(BANDAI, pose)
    take = write_positions(tmp_path / f"swing{suffix}", names, positions * 100.0, fps=30.0)
    assert main(["profile", str(bvh), "--out", str(tmp_path / "p.toml")]) == 0
    capsys.readouterr()
    joints = "joints = [" + ", ".join(f'"{n}"' for n in names) + "]"
    wrong = tmp_path / "wrong.toml"
    wrong.write_text((tmp_path / "p.toml").read_text().replace("[profile]\n", f"[profile]\nfps = 30\n{joints}\n", 1)
                     + 'forward = "left_wrist"\n')
    for path in (bvh, take):
        status, _, warnings = _run(capsys, "validate", "--body", wrong, path)
        assert status == 0 and len(warnings) == 1
        assert "the facing flips (turns by more than 115 degrees in a frame) in 8 of 240 frames" in warnings[0]
        assert _run(capsys, "validate", "--strict", "--body", wrong, path)[0] == 1


def test_a_kinect_csv_in_a_cameras_frame_checks_through_its_floor_and_files_table(tmp_path, capsys):
    """A profile's ``[files]`` table is applied to the file validated: the same checks, as the profile reads it."""
    from tests.fixtures.skeletons import KINECT, write_skeleton_csv

    (tmp_path / "kinect").mkdir()
    take = write_skeleton_csv(tmp_path / "kinect" / "k.csv", KINECT, human("wave") + np.array([0.0, -1.1, 2.0]),
                              scale=1000.0)
    assert main(["profile", str(take), "--out", str(tmp_path / "k.toml")]) == 0
    capsys.readouterr()
    text = (tmp_path / "k.toml").read_text()
    assert "floor = -1.08" in text and 'units = "millimetre"' in text
    assert _run(capsys, "validate", "--strict", "--body", tmp_path / "k.toml", take)[0] == 0
    metres = text.replace('units = "millimetre"', 'units = "metre"')
    (tmp_path / "m.toml").write_text(metres)
    assert _run(capsys, "validate", "--strict", "--body", tmp_path / "m.toml", take)[0] == 1
    (tmp_path / "m.toml").write_text(metres + '\n[files."kinect/*"]\nunits = "mm"\n')
    assert _run(capsys, "validate", "--strict", "--body", tmp_path / "m.toml", take)[0] == 0
