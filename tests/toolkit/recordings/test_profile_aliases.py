"""Several naming schemes of one skeleton in one repertoire: joint-name aliases and ``[files]`` tables of a profile."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fixtures.schemes import CMU_3DSMAX, CMU_MOTIONBUILDER, KINECT_V2_PARTS
from tests.fixtures.skeletons import human, write_skeleton_bvh, write_skeleton_csv
from toolkit import ConfigError
from toolkit.recordings.profile import load_profile

ROOT = Path(__file__).resolve().parents[3]


def _docs_example() -> str:
    """The profile of ``docs/conventions.md``'s "One skeleton, two naming schemes" (its first TOML block)."""
    text = (ROOT / "docs" / "conventions.md").read_text(encoding="utf-8")
    section = text[text.index("### One skeleton, two naming schemes"):]
    return re.search(r"```toml\n(.*?)```", section, re.S).group(1)


PROFILE = _docs_example()


def _write(folder, movement, name, *, turn, scheme):
    """A take of ``movement`` in the MotionBuilder names (centimetres) or the 3dsMax names (inches)."""
    folder.mkdir(parents=True, exist_ok=True)
    if scheme == "mb":
        return write_skeleton_bvh(folder / f"mb_{name}.bvh", CMU_MOTIONBUILDER, human(movement, turn=turn),
                                  scale=100.0)
    return write_skeleton_bvh(folder / f"max_{name}.bvh", CMU_3DSMAX, human(movement, turn=turn), scale=1 / 0.0254)


def test_the_first_alias_a_file_has_is_the_parts_joint(tmp_path, write):
    profile = load_profile(write("cmu.toml", PROFILE))
    assert profile.names[profile.body.parts.index("left_shoulder")] == ("LeftArm", "LeftShoulder")
    mb = profile.read(_write(tmp_path, "bow", "1", turn=0.2, scheme="mb"))
    mx = profile.read(_write(tmp_path, "bow", "1", turn=0.2, scheme="max"))
    # the same body in both names and units: LeftArm (not MotionBuilder's collar LeftShoulder) is the shoulder
    np.testing.assert_allclose(mb.positions, mx.positions, atol=1e-4)
    with profile.stream(tmp_path / "mb_1.bvh") as stream:
        assert stream.joints[profile.body.parts.index("left_shoulder")] == "LeftArm"
        assert stream.profile.scale == pytest.approx(0.01)
    with profile.stream(tmp_path / "max_1.bvh") as stream:
        assert stream.joints[profile.body.parts.index("left_shoulder")] == "LeftShoulder"
        assert stream.profile.scale == pytest.approx(0.0254)
    head = mb.positions[:, profile.body.parts.index("head")]
    assert 1.55 < head[0, 1] < 1.65  # metres, +y up


def test_a_repertoire_mixing_two_naming_schemes_recognises_both(tmp_path, write):
    from likeme.estimators import MovementClassifier, load_recordings

    profile = load_profile(write("cmu.toml", PROFILE))
    for movement in ("bow", "wave", "rest"):
        _write(tmp_path / "repertoire" / movement, movement, "a", turn=0.0, scheme="mb")
        _write(tmp_path / "repertoire" / movement, movement, "b", turn=0.3, scheme="max")
    demos = [("bow", "mb", -0.2), ("bow", "max", 0.1), ("wave", "max", -0.1), ("wave", "mb", 0.25),
             ("rest", "max", 0.0)]
    for k, (movement, scheme, turn) in enumerate(demos):
        _write(tmp_path / "demos" / movement, movement, f"d{k}", turn=turn, scheme=scheme)
    X, y, _ = load_recordings(tmp_path / "repertoire", profile)
    Xd, yd, _ = load_recordings(tmp_path / "demos", profile)
    assert sorted(y) == sorted(["bow", "wave", "rest"] * 2)
    predicted = MovementClassifier(profile).fit(X, y).predict(Xd)
    assert list(predicted) == list(yd)


def test_a_files_table_per_folder_gives_units_up_and_joints(tmp_path, write):
    """A ``[files."kinect/*"]`` table: the CSVs of that folder are in millimetres, z up, with their own joint names."""
    from tests.fixtures.skeletons import KINECT

    profile = load_profile(write("mixed.toml", PROFILE + """
[files."kinect/*"]
units = "mm"
up = "+z"

[files."kinect/*".parts]
""" + KINECT_V2_PARTS))
    (tmp_path / "kinect").mkdir()
    kinect = profile.read(write_skeleton_csv(tmp_path / "kinect" / "wave.csv", KINECT, human("wave"), scale=1000.0,
                                             up="+z"))
    cmu = profile.read(_write(tmp_path, "wave", "w", turn=0.3, scheme="mb"))
    assert kinect.parts == cmu.parts == profile.body.parts
    np.testing.assert_allclose(kinect.positions, cmu.positions, atol=1e-3)
    # outside the folder the profile's own reading holds: the same CSV there has none of [parts]' joints
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "wave.csv").write_bytes((tmp_path / "kinect" / "wave.csv").read_bytes())
    with pytest.raises(ConfigError, match="part 'root' is not in"):
        profile.read(tmp_path / "other" / "wave.csv")


def test_a_part_none_of_whose_aliases_a_file_has_names_them_all(tmp_path, write):
    profile = load_profile(write("cmu.toml", PROFILE.replace('chest = ["Spine1", "Chest2"]',
                                                             'chest = ["Spine1", "Chest3"]')))
    with pytest.raises(ConfigError) as info:
        profile.read(_write(tmp_path, "bow", "1", turn=0.0, scheme="max"))
    message = str(info.value)
    assert "cmu.toml:" in message and "key parts.chest" in message
    assert "none of 'Spine1', 'Chest3'" in message and "available: Hips, Chest, Chest2" in message


def test_a_files_tables_part_is_named_where_it_is_written(tmp_path, write):
    profile = load_profile(write("cmu.toml", PROFILE + '\n[files."max_*".parts]\nhead = "Skull"\n'))
    with pytest.raises(ConfigError) as info:
        profile.read(_write(tmp_path, "bow", "1", turn=0.0, scheme="max"))
    assert 'key files."max_*".parts.head' in str(info.value) and "'Skull'" in str(info.value)


@pytest.mark.parametrize("extra, expected", [
    ('[files."max_*".parts]\nnose = "Head"\n', "key files.\"max_*\".parts.nose: unknown part 'nose'"),
    ('[files."cmu/*"]\nfacing = 1\n', "unknown key 'facing'"),
    ('[files."max_*".parts]\nhead = ["Head", "Head"]\n', "joint names repeated"),
    ('[files."max_*".parts]\nhead = []\n', "invalid joint []"),
    ('[files."*.bvh"]\nup = "sky"\n', "key files.\"*.bvh\".up: unknown up axis 'sky'"),
    ('[files."*.csv"]\nfps = 0\n', "key files.\"*.csv\".fps: invalid fps 0"),
    ('[files."*.npy"]\njoints = ["Hips"]\n', "is not in the joints list"),
])
def test_a_bad_files_table_or_alias_is_named(write, extra, expected):
    text = PROFILE + extra
    with pytest.raises(ConfigError) as info:
        load_profile(write("bad.toml", text))
    assert expected in str(info.value)
    # the key's own line (quoted keys such as "*.bvh" read as TOML reads them: toolkit.config.toml.find_key_line)
    assert f"bad.toml:{PROFILE.count(chr(10)) + len(extra.splitlines())}:" in str(info.value)


def test_an_alias_list_reads_a_npy_array_by_its_joints_key(tmp_path, write):
    from tests.fixtures.skeletons import _skeleton_positions

    names, _, positions = _skeleton_positions(CMU_3DSMAX, human("bow"))
    np.save(tmp_path / "take.npy", positions * 100.0)
    profile = load_profile(write("cmu.toml", PROFILE.replace('name = "cmu-two-schemes"', 'name = "x"\nfps = 30\n'
                                                             f"joints = {names!r}".replace("'", '"'))))
    motion = profile.read(tmp_path / "take.npy")  # centimetres: the name is not max_*
    reference = profile.read(_write(tmp_path, "bow", "1", turn=0.3, scheme="max"))  # the same take, in inches
    np.testing.assert_allclose(motion.positions, reference.positions, atol=1e-4)
    assert profile.npy_joints == tuple(names)


@given(st.lists(st.sampled_from(["A", "B", "C", "D"]), min_size=1, max_size=4, unique=True),
       st.sets(st.sampled_from(["A", "B", "C", "D", "E"]), min_size=1))
def test_resolve_takes_the_first_alias_the_file_has(aliases, present):
    from toolkit.body import Body, Facing
    from toolkit.recordings.profile import BodyProfile

    body = Body(("root",), "root", Facing("root", "root"))
    profile = BodyProfile("p", body, (aliases[0],), aliases=(tuple(aliases),))
    names = sorted(present)
    first = next((a for a in aliases if a in present), None)
    if first is None:
        with pytest.raises(ConfigError, match="part 'root'"):
            profile.resolve(names)
    else:
        assert profile.resolve(names) == (first,)
        values = np.arange(len(names) * 3, dtype=float).reshape(1, len(names), 3)
        np.testing.assert_array_equal(profile.convert(values, names)[0, 0], values[0, names.index(first)])


def test_a_live_csv_in_either_naming_scheme_gives_the_files_poses(tmp_path, write):
    """``likeme observe -``: a tracker's CSV header in the 3dsMax names picks those aliases once, for every frame."""
    import io

    from tests.fixtures.skeletons import write_skeleton_csv as csv
    from toolkit.recordings.live import LiveInput

    profile = load_profile(write("cmu.toml", PROFILE))
    path = csv(tmp_path / "take.csv", CMU_3DSMAX, human("wave"), scale=100.0)
    live = np.array(list(LiveInput(io.BytesIO(path.read_bytes()), profile)))
    np.testing.assert_allclose(live, profile.read(path).positions, atol=1e-6)


def test_a_live_json_input_in_the_second_naming_scheme_gives_every_frame(tmp_path, write):
    """JSON lines naming the 3dsMax joints: every frame, the first included, in the aliases the input uses."""
    import io
    import json

    from tests.fixtures.skeletons import _skeleton_positions
    from toolkit.recordings.live import LiveInput

    profile = load_profile(write("cmu.toml", PROFILE))
    names, _, positions = _skeleton_positions(CMU_3DSMAX, human("wave"))
    lines = [json.dumps({"time": f / 30, **{n: list(positions[f, j] * 100) for j, n in enumerate(names)}})
             for f in range(len(positions))]
    live = np.array(list(LiveInput(io.BytesIO("\n".join(lines).encode()), profile)))
    reference = profile.read(_write(tmp_path, "wave", "1", turn=0.3, scheme="mb")).positions
    assert np.isfinite(live).all()
    np.testing.assert_allclose(live, reference, atol=1e-4)
