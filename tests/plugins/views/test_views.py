"""Views and rendered vision: off-screen pictures checked by their pixels.

Everything renders off screen (VTK's EGL window, no display). The pictures are
checked for real content: the parts' colours where the parts are, a known scene
against a stored low-resolution reference, files of the formats asked for.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from plugins.lib.rendering import draw_bodies, frame_2d, hex_to_rgb, part_colours, plotter
from tests.conftest import CHARACTERS, ROOT, STICK
from toolkit import World, create_plugin_manager, load_character
from likeme.cli import main
from toolkit.scenario import load_scenario

imageio = pytest.importorskip("imageio.v2")
REFERENCE = ROOT / "tests" / "fixtures" / "data" / "stick_body_64.png"


def _stick_image(write, size=64):
    pm = create_plugin_manager(autoload=False)
    stick = load_character(write("stick.toml", STICK), pm)
    pl = plotter((size, size))
    try:
        draw_bodies(pl, stick.body, stick.motor.rest_pose()[None], radius=0.08)
        frame_2d(pl, (-0.5, 0.3), (0.5, 1.8))
        return stick, np.asarray(pl.screenshot(return_img=True))[..., :3].astype(int)
    finally:
        pl.close()


def _has_colour(image, colour, tol=60):
    return (np.abs(image - np.array(hex_to_rgb(colour))).sum(axis=-1) < tol).sum()


def test_a_known_scene_matches_its_stored_low_resolution_reference(write):
    _, image = _stick_image(write)
    if not REFERENCE.exists():  # pragma: no cover - written once, then committed
        REFERENCE.parent.mkdir(exist_ok=True)
        imageio.imwrite(REFERENCE, image.astype(np.uint8))
    reference = imageio.imread(REFERENCE)[..., :3].astype(int)
    assert image.shape == reference.shape
    assert np.abs(image - reference).mean() < 6.0  # shading may differ by a few levels between drivers
    assert (image.sum(axis=-1) < 700).mean() > 0.02  # not an empty white picture


def test_every_part_colour_is_drawn_where_the_part_is(write):
    stick, image = _stick_image(write, size=128)
    colours = part_colours(stick.body)
    for part, colour in zip(stick.body.parts, colours):
        assert _has_colour(image, colour) > 3, f"{part} ({colour}) not drawn"
    # the head is above the knees: its colour's pixels sit higher in the picture (rows count from the top)
    rows = {p: np.nonzero(np.abs(image - np.array(hex_to_rgb(c))).sum(axis=-1) < 60)[0].mean()
            for p, c in zip(stick.body.parts, colours)}
    assert rows["head"] < rows["root"] < rows["lk"]


@pytest.mark.parametrize("view, args", [
    ("body", ["--set", "keys=3", "--set", 'movements=["jump", "wave"]', "--set", "width=400"]),
    ("posegraph", ["--set", "match=jump", "--set", "width=300", "--set", "height=240"]),
])
def test_show_draws_a_characters_view_to_png(tmp_path, capsys, view, args):
    out = tmp_path / f"{view}.png"
    assert main(["show", "max", "--view", view, "--out", str(out), *args]) == 0
    image = imageio.imread(out)[..., :3].astype(int)
    assert image.shape[1] in (300, 400)
    assert (np.abs(image - 255).sum(axis=-1) > 30).mean() > 0.01  # something drawn on the white background
    assert f"wrote {out}" in capsys.readouterr().out


def test_the_posegraph_view_highlights_the_matched_path(tmp_path):
    plain, matched = tmp_path / "plain.png", tmp_path / "matched.png"
    assert main(["show", "max", "--view", "posegraph", "--out", str(plain), "--set", "width=300", "--set", "height=240"]) == 0
    assert main(["show", "max", "--view", "posegraph", "--out", str(matched), "--set", "width=300", "--set", "height=240",
                 "--set", "match=wave", "--set", "demonstrator=morris"]) == 0
    red = [_has_colour(imageio.imread(p)[..., :3].astype(int), "#ff0000", tol=40) for p in (plain, matched)]
    assert red[1] > red[0] + 20


def test_the_motor_command_graph_view_after_the_imitation_games(tmp_path, capsys):
    out = tmp_path / "mcg.png"
    assert main(["show", "max", "--after", "imitation_games", "--view", "motor-command-graph", "--out", str(out),
                 "--set", "predict=left_side", "--set", "demonstrator=moritz", "--set", "width=300",
                 "--set", "height=260"]) == 0
    image = imageio.imread(out)[..., :3].astype(int)
    assert _has_colour(image, "#ff0000", tol=40) > 20  # the candidate edge and the active node


def test_a_view_of_the_wrong_subject_or_an_unknown_view_is_refused(capsys):
    assert main(["show", "max", "--view", "scenario"]) == 1
    assert "view 'scenario' draws a scenario, not a character" in capsys.readouterr().err
    assert main(["show", "max", "--view", "bodyy"]) == 1
    err = capsys.readouterr().err
    assert "unknown view 'bodyy'" in err and "available: body, correspondence, hub-signal, imitation, motor-command-graph" in err
    assert main(["show", "moritz", "--view", "posegraph"]) == 1
    assert "has no posegraph" in capsys.readouterr().err


def test_a_scenario_renders_to_png_frames_gif_and_mp4_at_its_frame_rate(tmp_path, capsys):
    out = tmp_path / "render"
    assert main(["run", "jump_then_cover_face", "--duration", "1.0", "--render", str(out), "--set", "every=3",
                 "--set", "width=200", "--set", "height=150"]) == 0
    frames = sorted(out.glob("frame_*.png"))
    assert len(frames) == 10  # 30 frames, one in three
    assert (out / "scenario.gif").stat().st_size > 1000 and (out / "scenario.mp4").stat().st_size > 1000
    gif = imageio.mimread(out / "scenario.gif")
    assert len(gif) == 10
    first = imageio.imread(frames[0])[..., :3].astype(int)
    assert _has_colour(first, "#b0b0b0", tol=10) + sum(_has_colour(first, c) for c in ("#ff0000", "#00ff00")) > 0


def test_the_scenario_view_greys_parts_the_observer_does_not_see(tmp_path):
    from plugins.views.scenario import ScenarioView

    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario("jump_then_cover_face", pm)
    scenario.duration = 0.2
    view = ScenarioView(formats=["png"], width=240, height=180)
    recorder = view.start(scenario.world)
    scenario.run()
    files = view.finish(recorder, tmp_path)
    assert len(files) == 6 and not pm.is_registered(recorder)
    seen = [s for s in recorder.seen["max"] if s is not None]
    assert seen and all(s.dtype == bool for s in seen)
    hidden = int(sum((~s).sum() for s in seen))
    grey = _has_colour(imageio.imread(files[-1])[..., :3].astype(int), "#b0b0b0", tol=6)
    assert (hidden == 0) or grey > 0


# -- rendered vision against synthetic vision


@pytest.fixture(scope="module")
def watching():
    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario("jump_then_cover_face", pm)
    return scenario.world


def test_rendered_vision_sees_what_synthetic_vision_sees_at_the_same_positions(watching):
    from plugins.perception.rendered_vision import RenderedVision
    from plugins.perception.synthetic_vision import SyntheticVision

    world = watching
    observer, target = world.actors["max"], world.actors["morris"]
    geometric, rendered = SyntheticVision(), RenderedVision(resolution=480)
    geometric.attach(observer.character)
    rendered.attach(observer.character)
    agree = total = 0
    errors = []
    try:
        for _ in range(150):  # the jump and the start of covering the face
            world.step()
            p1, s1, _ = geometric.look(observer, target, world)
            p2, s2, _ = rendered.look(observer, target, world)
            agree += int((s1 == s2).sum())
            total += len(s1)
            both = s1 & s2
            errors += list(np.linalg.norm(p1[both] - p2[both], axis=1))
            assert np.isnan(p2[~s2]).all()
    finally:
        rendered.close()
    assert agree / total > 0.95
    assert np.median(errors) < 0.01 and np.percentile(errors, 95) < 0.03  # metres


def test_rendered_vision_hides_a_part_behind_an_object_and_outside_the_field_of_view(write):
    from plugins.perception.rendered_vision import RenderedVision
    from toolkit import WorldObject

    pm = create_plugin_manager(autoload=False)
    stick = load_character(write("stick.toml", STICK), pm)
    world = World(fps=30, pm=pm)
    observer = world.add_actor(stick, "a")
    target = world.add_actor(load_character(write("stick2.toml", STICK.replace('"Stick"', '"Other"')), pm), "b",
                             position=(0, 0, 3), heading=np.pi)
    vision = RenderedVision(eye="head", resolution=320)
    vision.attach(observer.character)
    try:
        _, seen, _ = vision.look(observer, target, world)
        assert seen.all()
        head = target.world_pose()[target.body.index("head")]
        eye = observer.world_pose()[observer.body.index("head")]
        world.add_object(WorldObject("board", "board", position=eye + (head - eye) * 0.5, radius=0.15, colour="#336699"))
        _, seen, objects = vision.look(observer, target, world)
        assert not seen[target.body.index("head")] and seen[target.body.index("lk")] and len(objects) == 1
        np.testing.assert_allclose(objects.positions[0], eye + (head - eye) * 0.5, atol=0.03)
        assert objects.radii[0] == pytest.approx(0.15, abs=0.02)  # its size as seen: the blob and its depth
        np.testing.assert_array_equal(objects.colours[0], [0x33, 0x66, 0x99])
        observer.heading = np.pi  # turn away: nothing of the target is in view
        _, seen, _ = vision.look(observer, target, world)
        assert not seen.any()
    finally:
        vision.close()


def test_max_watches_with_rendered_vision_and_synthetic_vision_is_the_fast_setting(write):
    """Max's own perception is the colour-coded rendering (§4.2); the geometric synthetic vision, his eye, part radii
    and looks kept, finds the same two movements."""
    from plugins.perception.rendered_vision import RenderedVision
    from tests.plugins.perception.test_synthetic_vision import geometric

    pm = create_plugin_manager(autoload=False)
    scenario = load_scenario("jump_then_cover_face", pm)
    assert isinstance(scenario.world.actors["max"].character.perception, RenderedVision)
    world = scenario.run()
    assert [e.data["match"].movement for e in world.events_of("movement_recognised", "max")] == ["jump", "cover_face"]
    text = (CHARACTERS / "scenarios" / "jump_then_cover_face.toml").read_text().replace('"../', f'"{CHARACTERS}/')
    table = "".join(f"{k} = {_toml(v)}\n" for k, v in geometric(pm).items())
    path = write("geometric.toml", text + "[actors.override.perception]\n" + table)
    scenario = load_scenario(path, pm)
    assert scenario.world.actors["max"].character.perception.name == "synthetic-vision"
    world = scenario.run()
    assert [e.data["match"].movement for e in world.events_of("movement_recognised", "max")] == ["jump", "cover_face"]


def _toml(value):
    """A value written as TOML (the few kinds a perception table holds)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return repr(value)


def test_a_third_party_view_registers_through_the_hook_and_draws(tmp_path):
    from tests.conftest import make_plugin
    from toolkit import View
    from toolkit.manager import PluginInfo

    class Outline(View):
        """The hub pose's parts as a text file (a view needs no drawing library)."""

        name = "outline"

        def draw(self, subject, out):
            out = Path(out)
            out.write_text("\n".join(f"{p} {x:.2f} {y:.2f} {z:.2f}" for p, (x, y, z) in
                                     zip(subject.body.parts, subject.motor.rest_pose())))
            return [out]

    pm = create_plugin_manager(autoload=False)
    pm.register_plugin(make_plugin(likeme_register_views=lambda: [Outline]), PluginInfo("outline", "m", "(tests)", ""))
    assert "outline" in pm.registry.names("view") and "body" in pm.registry.names("view")
    max_ = load_character("max", pm)
    files = pm.registry.get("view", "outline")().draw(max_, tmp_path / "max.txt")
    assert files[0].read_text().splitlines()[0].startswith(max_.body.parts[0])


def test_the_vision_benchmark_compares_both_perceptions_on_the_same_frames():
    from plugins.bench.vision import vision_benchmark

    rows = vision_benchmark(create_plugin_manager(autoload=False), "jump_then_cover_face", "max", [240], 20)
    assert [r["perception"] for r in rows] == ["synthetic-vision", "rendered-vision 240 px"]
    assert rows[1]["agreement"] > 0.9 and 0 < rows[1]["median_mm"] < 30 and rows[1]["ms_per_frame"] > 0


def test_every_scenario_runs_with_either_eye_and_concludes_the_same():
    """``likeme bench vision --scenarios`` on one scenario: Max's rendered eye and the geometric one in its place
    find the same movements and behaviours about the same objects of the world."""
    from plugins.bench.vision import scenario_benchmark

    (row,) = scenario_benchmark(create_plugin_manager(autoload=False), ["cheese_or_ball"], repeats=1)
    assert row["perception"] == "rendered-vision" and row["same"]
    assert row["seconds"] > 0 and row["synthetic_seconds"] > 0
