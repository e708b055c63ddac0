"""A profile's ``[facing]`` with several left/right pairs (``left = ["left_hip", "left_shoulder"]``): read, written
back and read again; an old profile (one part each) reads as before; a bad one names the key, what was expected
and what is available."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from toolkit import ConfigError
from toolkit.body import Body, Facing
from toolkit.recordings.profile import load_profile

PARTS = ("root", "head", "left_hip", "right_hip", "left_shoulder", "right_shoulder", "left_knee", "right_knee",
         "left_toes", "left_toe_tip")

PROFILE = """[profile]
name = "pairs"
units = "cm"

[parts]
{parts}

[facing]
{facing}
forward = "left_toe_tip"
behind = "left_toes"
"""


def _profile(write, facing: str, name: str = "p.toml"):
    parts = "\n".join(f'{p} = "J_{p}"' for p in PARTS)
    return write(name, PROFILE.format(parts=parts, facing=facing))


def test_several_pairs_are_read_first_pair_first(write):
    path = _profile(write, 'left = ["left_hip", "left_shoulder"]\nright = ["right_hip", "right_shoulder"]')
    facing = load_profile(path).body.facing
    assert facing.pairs == (("left_hip", "right_hip"), ("left_shoulder", "right_shoulder"))
    assert (facing.left, facing.right, facing.forward, facing.behind) == ("left_hip", "right_hip", "left_toe_tip",
                                                                           "left_toes")


@pytest.mark.parametrize("facing", ['left = "left_hip"\nright = "right_hip"',
                                    'left = ["left_hip"]\nright = ["right_hip"]'])
def test_one_pair_reads_as_before_whether_named_or_listed(write, facing):
    assert load_profile(_profile(write, facing)).body.facing == Facing("left_hip", "right_hip", "left_toe_tip",
                                                                       "left_toes")


@settings(max_examples=40, deadline=None)
@given(pairs=st.lists(st.sampled_from([("left_hip", "right_hip"), ("left_shoulder", "right_shoulder"),
                                       ("left_knee", "right_knee"), ("right_knee", "left_knee")]),
                      min_size=1, max_size=4, unique=True),
       forward=st.booleans())
def test_a_facing_written_as_a_table_reads_back_the_same(pairs, forward):
    facing = Facing(*pairs[0], "left_toe_tip" if forward else None, "left_toes" if forward else None,
                    tuple(pairs[1:]))
    table = {"parts": list(PARTS), "root": "root", "facing": facing.table()}
    assert Body.from_config(table).facing == facing
    assert isinstance(table["facing"]["left"], str) == (len(pairs) == 1)  # one pair: written as the old profiles


@pytest.mark.parametrize(
    "facing, expected",
    [
        ('left = ["left_hip", "left_shoulder"]\nright = "right_hip"',
         ["key facing.right", "expected a non-empty list of part names, one per pair, as left is", "available: root"]),
        ('left = ["left_hip", "left_shoulder"]\nright = ["right_hip"]',
         ["key facing.right", "2 left parts and 1 right parts", "expected one right part for each left part"]),
        ('left = []\nright = []', ["key facing.left", "expected a non-empty list of part names"]),
        ('left = ["left_hip", 3]\nright = ["right_hip", "right_shoulder"]', ["key facing.left", "invalid"]),
        ('left = ["left_hip", "left_sholder"]\nright = ["right_hip", "right_shoulder"]',
         ["key facing.left[1]", "unknown body part 'left_sholder'", "available: root, head, left_hip"]),
        ('left = ["left_hip", "left_shoulder"]\nright = ["right_hip", "left_shoulder"]',
         ["key facing.right[1]", "left and right are the same part 'left_shoulder'"]),
        ('left = ["left_hip", "left_hip"]\nright = ["right_hip", "right_hip"]',
         ["key facing.left", "a left/right pair given twice"]),
        ('left = 3\nright = "right_hip"', ["key facing.left", "expected a part name, or a list of part names"]),
    ],
)
def test_a_bad_facing_names_the_file_the_key_what_was_expected_and_what_is_available(write, facing, expected):
    path = _profile(write, facing, "bad.toml")
    with pytest.raises(ConfigError) as info:
        load_profile(path)
    message = str(info.value)
    assert message.startswith(f"{path}:"), message
    for text in expected:
        assert text in message, message


def test_an_observer_composed_from_the_profile_keeps_every_pair(write):
    """``likeme observe`` and the benchmarks give the observer the profile's body: the forward model watches a
    performance with it, so it must find the facing as the repertoire's clips were read (toolkit/observe.py)."""
    import numpy as np

    from plugins.lib.clip_repertoire import clip_repertoire
    from toolkit import create_plugin_manager
    from toolkit.motion import Motion
    from toolkit.observe import compose_observer

    profile = load_profile(_profile(write, 'left = ["left_hip", "left_shoulder"]\nright = ["right_hip", '
                                           '"right_shoulder"]'))
    rest = np.array([[0, 0.95, 0], [0, 1.7, 0], [0.065, 0.95, 0], [-0.065, 0.95, 0], [0.17, 1.45, 0], [-0.17, 1.45, 0],
                     [0.08, 0.5, 0], [-0.08, 0.5, 0], [0.1, 0.0, 0.08], [0.1, 0.0, 0.12]])
    clips = []
    for axis in (0, 1):  # the head nods forward, or leans to the left
        positions = np.repeat(rest[None], 30, axis=0)
        positions[:, 1, 2 * (1 - axis)] += 0.1 * np.sin(np.linspace(0, np.pi, 30))
        clips.append(Motion(positions, 30.0, PARTS))
    repertoire = clip_repertoire(clips, ["nod", "lean"], profile)
    observer = compose_observer(create_plugin_manager(), profile, repertoire, matcher="dtw")
    assert observer.body.facing == profile.body.facing
