"""Rendered vision (B&B §4.2): the picture Max's eye gets, scanned by colour; its docs block runs as written."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.perception.colour_scan import pack, scan, unpack, unproject
from plugins.perception.object_looks import Looks, rgb_of
from plugins.perception.object_tracking import Detections, ObjectTracker
from tests.conftest import CHARACTERS
from toolkit import ConfigError

ROOT = CHARACTERS.parent


def test_the_vision_page_draws_what_max_sees(tmp_path, monkeypatch):
    """docs/vision.md's Python block, run as written (its picture written here): Morris in his colours, the cheese's
    gold and the ball's red beside his reaching hand."""
    import imageio.v2 as imageio

    block = re.search(r"```python\n(.*?)```", (ROOT / "docs" / "vision.md").read_text(), re.S).group(1)
    out = tmp_path / "eye.png"
    block = block.replace('"docs/images/max-eye-objects-close-together.png"', repr(str(out)))
    exec(compile(block, "docs/vision.md", "exec"), {})
    picture = imageio.imread(out)[::6, ::6, :3].reshape(-1, 3)
    colours = {tuple(c) for c in picture}
    for wanted in ("#ff00ff", "#ffff00", "#ff0000", "#ffd700", "#ff4040"):  # head, nose, right hand, cheese, ball
        assert tuple(int(v) for v in rgb_of(wanted)) in colours, wanted


def test_scan_finds_each_parts_pixels_and_each_blob_of_another_colour():
    image = np.zeros((20, 20, 3), dtype=np.uint8)
    depth = np.full((20, 20), np.inf)
    image[2:5, 2:5] = (255, 0, 255)  # a part, 9 pixels
    depth[2:5, 2:5] = 2.0
    image[10:12, 3:5] = image[10:12, 15:17] = (255, 215, 0)  # two blobs of one colour, apart
    depth[10:12, 3:5], depth[10:12, 15:17] = 1.5, 3.0
    image[18, 0:3] = (80, 80, 80)  # limbs: body, not tracked
    depth[18, 0:3] = 1.0
    drawn = np.isfinite(depth)
    rows, cols = np.nonzero(drawn)
    keys = pack(image[rows, cols])
    found = scan(keys, rows, cols, depth[rows, cols], {int(pack(np.array([255, 0, 255]))): 1,
                                                       int(pack(np.array([80, 80, 80]))): -1}, 3)
    assert found.part_pixels.tolist() == [0, 9, 0] and (found.part_u[1], found.part_v[1]) == (3.0, 3.0)
    assert found.part_near[1] == 2.0 and np.isnan(found.part_near[0])
    assert sorted(found.blob_pixels.tolist()) == [4, 4] and sorted(found.blob_near.tolist()) == [1.5, 3.0]
    np.testing.assert_array_equal(found.blob_colours, [[255, 215, 0]] * 2)
    np.testing.assert_array_equal(unpack(int(pack(np.array([1, 2, 3])))), [1, 2, 3])


def test_unproject_puts_the_middle_pixel_straight_ahead():
    point = unproject(np.array([49.5]), np.array([49.5]), np.array([2.0]), (100, 100), 90.0)
    np.testing.assert_allclose(point, [[0.0, 0.0, 2.0]], atol=1e-12)
    edge = unproject(np.array([-0.5]), np.array([49.5]), np.array([1.0]), (100, 100), 90.0)
    np.testing.assert_allclose(edge, [[-1.0, 0.0, 1.0]], atol=1e-12)  # the left edge of a 90 degree view


def test_a_look_tells_a_kind_by_its_colour_and_size_and_says_why():
    looks = Looks({"cheese": {"colour": "#ffd700", "radius": [0.02, 0.1]}, "ball": {"colour": "#ff4040"}}, 60.0)
    kind = looks.kind("#ffd000", 0.04)
    assert kind == "cheese" and "colour #ffd000 is 7 from cheese" in kind.reason
    assert looks.kind("#ffd700", 0.5) == "thing #ffd700"  # a cheese's colour, far too big
    assert "outside cheese" in looks.kind("#ffd700", 0.5).reason
    assert looks.kind("#0000ff", 0.04) == "thing #0000ff" and "tolerance 60" in looks.kind("#0000ff", 0.04).reason
    assert Looks({}, 60.0).kind("#ffd700", 0.04) == "thing #ffd700"
    for table, message in [({"cheese": "#ffd700"}, "key looks.cheese: invalid look"),
                           ({"cheese": {"colour": "yellow"}}, "key looks.cheese.colour: invalid colour"),
                           ({"cheese": {"colour": "#ffd700", "radius": [0.2, 0.1]}}, "key looks.cheese.radius"),
                           ({"cheese": {"colour": "#ffd700", "size": 1}}, "key looks.cheese.size: unknown key")]:
        with pytest.raises(ConfigError, match=message):
            Looks(table, 60.0)


def test_the_tracker_keeps_names_as_objects_move_and_names_new_ones_by_their_look():
    looks = Looks({"cheese": {"colour": "#ffd700"}}, 60.0)
    tracker = ObjectTracker(looks, gate=0.15)
    gold = rgb_of("#ffd700")

    def seen(*positions, colour=gold):
        return Detections(np.array(positions, dtype=float), np.full(len(positions), 0.04), np.tile(colour, (len(positions), 1)))

    names, kinds, _ = tracker.update(seen([0, 0, 1], [0.5, 0, 1]))
    assert list(names) == ["cheese", "cheese 2"] and kinds["cheese 2"] == "cheese"
    names, _, _ = tracker.update(seen([0.52, 0, 1], [0.03, 0, 1]))  # both moved a little, listed the other way
    assert np.allclose(names["cheese"], [0.03, 0, 1]) and np.allclose(names["cheese 2"], [0.52, 0, 1])
    names, _, _ = tracker.update(seen([0.03, 0, 1], [1.5, 0.3, 1.2]))  # the second vanished, one appeared: moved
    assert set(names) == {"cheese", "cheese 2"} and np.allclose(names["cheese 2"], [1.5, 0.3, 1.2])
    names, kinds, _ = tracker.update(seen([3, 0, 3], colour=rgb_of("#0000ff")))
    assert list(names) == ["thing #0000ff"]


def test_reading_back_the_rectangle_of_what_is_drawn_gives_what_the_whole_picture_gives(monkeypatch):
    """Only the rectangle every drawn sphere falls in is read back: the same parts, places and objects as reading
    the whole picture, frame by frame (max_acts_then_watches: Max's own ball and cheese low in his view too)."""
    import plugins.perception.rendered_vision as rv
    from toolkit import create_plugin_manager, load_scenario

    world = load_scenario("max_acts_then_watches", create_plugin_manager(autoload=False)).world
    max_ = world.actors["max"]
    vision, whole = max_.character.perception, (lambda centres, radii, eye, axes, size, angle: (0, 0, size - 1, size - 1))
    for frame in range(0, 300):
        world.step()
        if frame % 10:
            continue
        looks = []
        for window in (rv._window, whole):
            with monkeypatch.context() as m:
                m.setattr(rv, "_window", window)
                vision._camera_rng = np.random.default_rng(frame)
                looks.append(vision.look(max_, max_.target, world))
        (p1, s1, d1), (p2, s2, d2) = looks
        np.testing.assert_array_equal(s1, s2)
        np.testing.assert_allclose(p1[s1], p2[s2], atol=1e-9)
        np.testing.assert_allclose(d1.positions, d2.positions, atol=1e-9)


def test_a_parts_colour_in_two_places_is_the_part_where_it_was_and_an_object_elsewhere():
    """A ball painted the left hand's blue: the hand is the blob of blue nearest where the hand was, the other a
    thing of that colour."""
    image = np.zeros((40, 40, 3), dtype=np.uint8)
    depth = np.full((40, 40), np.inf)
    image[10:14, 10:14] = image[30:36, 30:36] = (0, 0, 255)
    depth[10:14, 10:14], depth[30:36, 30:36] = 1.6, 1.2
    image[12:15, 20:23] = (255, 0, 255)  # another part, the rest of the body
    depth[12:15, 20:23] = 1.6
    rows, cols = np.nonzero(np.isfinite(depth))
    known = {int(pack(np.array([0, 0, 255]))): 0, int(pack(np.array([255, 0, 255]))): 1}
    args = (pack(image[rows, cols]), rows, cols, depth[rows, cols], known, 2)
    for previous in (None, np.array([[11.0, 11.0], [np.nan, np.nan]])):  # near the body; where it was
        found = scan(*args, previous=previous)
        assert found.part_pixels[0] == 16 and (found.part_u[0], found.part_v[0]) == (11.5, 11.5)
        assert found.blob_pixels.tolist() == [36.0] and found.blob_near.tolist() == [1.2]
    found = scan(*args, previous=np.array([[33.0, 33.0], [np.nan, np.nan]]))  # the hand was over there
    assert found.part_pixels[0] == 36 and found.blob_pixels.tolist() == [16.0]


def test_a_character_whose_parts_look_alike_is_refused_when_it_is_loaded(write):
    from toolkit import create_plugin_manager, load_character

    path = write("alike.toml", f'[character]\nname = "Max"\nextends = "{CHARACTERS / "max.toml"}"\n'
                               '[body.colours]\nnose = "#ff00ff"\n')
    with pytest.raises(ConfigError, match=r"Max's \[body.colours\]: part 'nose' and 'head' look alike \(#ff00ff\)"):
        load_character(path, create_plugin_manager(autoload=False))


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6), st.integers(0, 10_000))
def test_objects_that_move_a_little_each_frame_keep_their_names(n, seed):
    """Any number of objects of one colour, each moving a few centimetres a frame and at least 30 cm from the
    others, keep the names they were first given, in whatever order the eye lists them."""
    rng = np.random.default_rng(seed)
    tracker = ObjectTracker(Looks({"cheese": {"colour": "#ffd700"}}, 60.0), gate=0.15)
    where = np.array([[0.4 * i, 0.0, 1.0] for i in range(n)])
    names = None
    for frame in range(30):
        where = where + rng.uniform(-0.03, 0.03, where.shape)  # a few centimetres each frame
        order = rng.permutation(n)
        seen, _, _ = tracker.update(Detections(where[order], np.full(n, 0.04), np.tile(rgb_of("#ffd700"), (n, 1))))
        by_place = {tuple(np.round(p, 6)): name for name, p in seen.items()}
        now = [by_place[tuple(np.round(p, 6))] for p in where]
        if names is None:
            names = now
            assert sorted(names) == sorted(["cheese"] + [f"cheese {k}" for k in range(2, n + 1)])
        assert now == names
