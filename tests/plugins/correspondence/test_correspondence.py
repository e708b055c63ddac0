"""Correspondence: another body's size and rest posture mapped onto one's own (B&B §7.1, K&G §6).

Unit tests of each formula (body size, rest posture, attention), the ``body-mapping`` plugin on a small rigid
skeleton the test builds, the watching loop with and without it, and the open-set recognition protocol.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.correspondence.body_mapping import BodyMapping
from plugins.lib.body_size import RunningLengths, bone_lengths, bone_tree, retarget, rigid_pairs
from plugins.lib.pose_distance import pose_distance
from plugins.lib.rest_posture import RestPosture
from toolkit import Motion
from toolkit.body import Body, Facing

FPS = 30.0
PARTS = ("root", "chest", "head", "left_hand", "right_hand", "left_foot", "right_foot")
BONES = (("root", "chest"), ("chest", "head"), ("chest", "left_hand"), ("chest", "right_hand"),
         ("root", "left_foot"), ("root", "right_foot"))
REST = np.array([[0, 0, 0], [0, 0.5, 0], [0, 0.8, 0.05], [0.35, 0.3, 0], [-0.35, 0.3, 0], [0.15, -0.9, 0],
                 [-0.15, -0.9, 0]], dtype=float)


def wave(n: int = 60, *, rest: np.ndarray = REST, amplitude: float = 1.2) -> np.ndarray:
    """The left hand swings up and back about the chest at its arm's length (a rigid skeleton)."""
    out = np.repeat(rest[None], n, axis=0)
    arm = rest[3] - rest[1]
    for f, a in enumerate(amplitude * np.sin(np.linspace(0, np.pi, n))):
        out[f, 3] = out[f, 1] + _swing(arm, a)
    return out


def _swing(arm: np.ndarray, angle: float) -> np.ndarray:
    """The arm vector turned up by ``angle`` about the forward axis."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * arm[0] - s * arm[1], s * arm[0] + c * arm[1], arm[2]])


def own_body() -> SimpleNamespace:
    body = Body(PARTS, "root", Facing("left_foot", "right_foot"), bones=BONES)
    examples = [("wave", Motion(wave(), FPS, PARTS)), ("stand", Motion(np.repeat(REST[None], 20, axis=0), FPS, PARTS))]
    motor = SimpleNamespace(rest_pose=lambda: REST.copy(), examples=lambda fps=FPS: examples)
    return SimpleNamespace(body=body, motor=motor, name="tester")


def mapping(**params) -> BodyMapping:
    component = BodyMapping(**params)
    component.attach(own_body())
    component.reset(PARTS, FPS)
    return component


def demonstrator(scale: float, lean: float, n_still: int = 45) -> np.ndarray:
    """Someone ``scale`` times the observer's size whose rest posture leans the head and chest forward by ``lean``
    (m): stands still, then waves, then stands again."""
    rest = REST * scale
    rest[1:3, 2] += lean
    still = np.repeat(rest[None], n_still, axis=0)
    return np.concatenate([still, wave(rest=rest), still])


# -- formulas -------------------------------------------------------------------------------------------


def test_the_bone_tree_runs_outward_from_the_root():
    tree = bone_tree(PARTS, BONES, "root")
    seen = {0}
    for parent, child in tree:
        assert parent in seen  # a parent always comes before its children
        seen.add(child)
    assert seen == set(range(len(PARTS)))


def test_retarget_keeps_directions_and_sets_lengths():
    tree = bone_tree(PARTS, BONES, "root")
    poses = wave() * 1.3
    lengths = bone_lengths(poses, np.ones(poses.shape[:2], bool), tree)
    own = bone_lengths(REST[None], np.ones((1, len(PARTS)), bool), tree)[0]
    out = retarget(poses, tree, own / lengths, 0)
    np.testing.assert_allclose(bone_lengths(out, np.ones(poses.shape[:2], bool), tree), np.broadcast_to(own, lengths.shape))
    np.testing.assert_allclose(out, wave(), atol=1e-12)  # the same movement at one's own size
    np.testing.assert_allclose(retarget(poses, tree, np.ones(len(tree)), 0), poses)  # ratio 1: as it was


def test_rigid_pairs_are_the_links_that_keep_their_length():
    pairs, lengths = rigid_pairs([(wave(), np.ones((60, len(PARTS)), bool))], np.ones(len(PARTS), bool))
    found = {(PARTS[i], PARTS[j]) for i, j in pairs}
    assert ("chest", "left_hand") in found and ("root", "head") in found
    assert ("root", "left_hand") not in found  # the hand moves about the chest, not about the root
    assert np.all(lengths > 0)


@given(st.lists(st.integers(1, 20), min_size=1, max_size=6))
@settings(max_examples=30, deadline=None)
def test_running_lengths_are_the_causal_mean_whatever_the_blocks(sizes):
    rng = np.random.default_rng(1)
    values = rng.uniform(0.2, 0.4, size=(sum(sizes), 3))
    values[rng.random(values.shape) < 0.3] = np.nan
    running = RunningLengths(3)
    got = np.concatenate([running.update(values[a:b]) for a, b in _blocks(sizes)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # nanmean of a column not seen yet
        expected = np.array([np.nanmean(values[: i + 1], axis=0) for i in range(len(values))])
    np.testing.assert_allclose(got, expected, equal_nan=True)


def test_rest_posture_is_where_the_body_dwells():
    rest = demonstrator(1.0, 0.08)
    estimate = RestPosture(len(PARTS), FPS, dwell_speed=0.05, window=0.5, memory=30.0, prior=REST)
    found = estimate.update(rest, np.ones(rest.shape[:2], bool), size=0.45)
    dwell = rest[0]
    assert pose_distance(found[44], dwell) < 1e-3  # after 1.5 s standing: their own stance
    assert pose_distance(found[-1], dwell) < 0.01  # the wave in between moved it little
    moving = wave(n=40)
    early = RestPosture(len(PARTS), FPS, dwell_speed=0.05, window=0.5, memory=30.0, prior=REST).update(
        moving, np.ones(moving.shape[:2], bool), size=0.45)
    assert pose_distance(early[30], REST) < 0.05  # never still: one's own rest is assumed


# -- the plugin --------------------------------------------------------------------------------------------


def test_body_mapping_turns_a_larger_leaning_demonstrator_into_ones_own_movement():
    seen = demonstrator(1.25, 0.08)
    vis = np.ones(seen.shape[:2], bool)
    plain = pose_distance(seen[45:105], wave())
    mapped = mapping().map_block(seen, vis)
    assert np.nanmean(pose_distance(mapped[45:105], wave())) < 0.1 * np.nanmean(plain)
    assert np.nanmean(pose_distance(mapped[:45], REST)) < 0.01  # their stance reads as one's own rest


def test_inspect_reports_the_estimates_so_far():
    component = mapping()
    np.testing.assert_allclose(component.inspect()["rest"], REST)  # nothing seen yet: one's own rest
    component.map_block(demonstrator(1.25, 0.0)[:45], np.ones((45, len(PARTS)), bool))
    signals = component.inspect()
    np.testing.assert_allclose(signals["their_lengths"], 1.25 * signals["own_lengths"])
    stance = demonstrator(1.25, 0.08)[:45]
    unsized = mapping(size="none")
    unsized.map_block(stance, np.ones((45, len(PARTS)), bool))
    assert pose_distance(unsized.inspect()["rest"], stance[0]) < 0.01  # their stance (the prior weighs one frame)


def test_each_step_can_be_switched_off():
    seen = demonstrator(1.25, 0.0)
    vis = np.ones(seen.shape[:2], bool)
    np.testing.assert_allclose(mapping(size="none", rest="none").map_block(seen, vis), seen)
    sized = mapping(rest="none").map_block(seen, vis)
    np.testing.assert_allclose(sized, demonstrator(1.0, 0.0), atol=1e-9)


@given(st.lists(st.integers(1, 40), min_size=1, max_size=5))
@settings(max_examples=25, deadline=None)
def test_mapping_does_not_depend_on_how_frames_are_packed(sizes):
    seen = demonstrator(1.1, 0.05)[: sum(sizes)]
    vis = np.ones(seen.shape[:2], bool)
    whole = mapping().map_block(seen, vis)
    split = mapping()
    parts = np.concatenate([split.map_block(seen[a:b], vis[a:b]) for a, b in _blocks(sizes)])
    np.testing.assert_allclose(parts, whole, atol=1e-9)


def test_hidden_parts_are_mapped_from_where_they_were_last_seen():
    seen = demonstrator(1.2, 0.05)
    vis = np.ones(seen.shape[:2], bool)
    vis[50:70, PARTS.index("left_hand")] = False
    out = mapping().map_block(seen, vis)
    assert np.isfinite(out).all()


# -- helpers -----------------------------------------------------------------------------------------------


def _blocks(sizes):
    edges = np.concatenate([[0], np.cumsum(sizes)])
    return list(zip(edges[:-1], edges[1:]))


# -- in the observer ---------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    from plugins.bench.data import make_data
    from toolkit import create_plugin_manager

    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("generated"), seed=5, streams=1, per_stream=3)


def test_body_mapping_in_the_observer_and_the_template_is_the_papers_observer(generated, pm):
    from toolkit.observe import Observer, compose_observer
    from toolkit.recordings.profile import load_profile

    profile = load_profile(generated / "profile.toml")
    mapped = compose_observer(pm, profile, generated / "repertoire", correspondence="body-mapping")
    plain = compose_observer(pm, profile, generated / "repertoire")
    assert mapped.correspondence.name == "body-mapping" and plain.correspondence is None
    assert compose_observer(pm, profile, generated / "repertoire", correspondence="none").correspondence is None
    motion = profile.read(sorted((generated / "streams").glob("*.bvh"))[0])
    watching = Observer(mapped, profile.body, motion.fps)
    watching.watch(motion)
    loop = watching.loop
    assert loop.perceived is not None and loop.perceived.n == loop.memory.n == motion.n_frames
    plain_observer = Observer(plain, profile.body, motion.fps)
    plain_observer.watch(motion)
    assert plain_observer.loop.perceived is None
    np.testing.assert_allclose(loop.perceived.positions, plain_observer.memory.positions)  # what was perceived
    # Max watching Morris (the same body): his four rigid links are Max's lengths, so little changes; his rest is Max's
    assert np.nanmax(np.abs(loop.memory.positions - plain_observer.memory.positions)) < 0.05


@pytest.mark.benchmark
def test_open_protocol_counts_unknown_as_right_for_a_movement_left_out(generated, pm):
    from plugins.bench.mocap import recognition
    from toolkit.recordings.profile import load_profile

    profile = load_profile(generated / "profile.toml")
    result = recognition(pm, profile, generated / "repertoire", generated / "demos", ["path-search"],
                         protocol="open", observer={"template": "papers"})
    row = result["plugins"][0]
    assert {item["truth"] for item in result["items"]} == {"unknown"}
    right = [item["recognised"] == "unknown" for item in result["items"]]
    assert row["rejection"] == pytest.approx(np.mean(right)) and np.isnan(row["known_accuracy"])
    assert row["rejection"] > 0.5  # path search's max_distance rejects most movements it does not know
    rejected = [item for item in result["items"] if item["recognised"] == "unknown" and item["nearest"]]
    assert rejected and all(item["nearest"] != item["movement"] for item in rejected)  # it was left out


def test_observe_says_why_a_segment_is_unknown(generated, capsys):
    from likeme.cli import main

    profile = generated / "profile.toml"
    demo = sorted((generated / "demos").glob("*/*.bvh"))[0]
    assert main(["observe", str(demo), "--body", str(profile), "--repertoire", str(generated / "repertoire"),
                 "--observer", "papers", "--set", "matcher.distance.max_distance=1e-9", "--json"]) == 0
    import json

    segments = json.loads(capsys.readouterr().out)[0]["segments"]
    assert segments and all(s["movement"] == "unknown" for s in segments)
    assert all(s["reason"] == "too far from every path" and s["nearest"] and s["score"] > s["threshold"] == 1e-9
               and s["measure"] == "mean pose distance along the path (eq. 3)" for s in segments)
    assert main(["observe", str(demo), "--body", str(profile), "--repertoire", str(generated / "repertoire"),
                 "--observer", "papers", "--set", "matcher.distance.max_distance=1e-9"]) == 0
    assert "rejected: too far from every path (mean pose distance along the path (eq. 3) 0." in capsys.readouterr().out


def test_observe_json_ranks_the_forward_models_candidates(generated, capsys):
    """`likeme observe --json` gives the matcher's ranked candidates (Fig. 13): the forward model's movements by
    their prediction error, the answer first and the others from the nearest, known or not."""
    import json

    from likeme.cli import main

    demo = sorted((generated / "demos").glob("*/*.bvh"))[0]
    args = ["observe", str(demo), "--body", str(generated / "profile.toml"), "--repertoire",
            str(generated / "repertoire"), "--matcher", "forward-model", "--json"]
    assert main(args) == 0
    segments = json.loads(capsys.readouterr().out)[0]["segments"]
    ranked = [s for s in segments if s.get("candidates")]
    assert ranked, "the forward model ranked nothing"
    for s in ranked:
        names, errors = [c[0] for c in s["candidates"]], [c[1] for c in s["candidates"]]
        assert len(set(names)) == len(names) and all(e >= 0 for e in errors)
        assert errors[1:] == sorted(errors[1:])
        if s["movement"] != "unknown":
            assert names[0] == s["movement"]


def test_likeme_show_draws_a_recording_as_perceived_and_as_mapped(generated, tmp_path, capsys):
    from PIL import Image

    from likeme.cli import main

    demo = sorted((generated / "demos").glob("*/*.bvh"))[0]
    common = ["show", "observers/recordings", "--body", str(generated / "profile.toml"), "--repertoire",
              str(generated / "repertoire"), "--view", "correspondence", "--set", f"recording={demo}"]
    out = tmp_path / "mapped.png"
    assert main([*common, "--correspondence", "body-mapping", "--out", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    image = np.asarray(Image.open(out).convert("L"))
    assert image.shape[1] == 1600 and (image < 128).mean() > 0.001  # bodies drawn, not a blank page
    assert main([*common, "--correspondence", "none", "--out", str(tmp_path / "plain.png")]) == 1
    assert "has no correspondence" in capsys.readouterr().err
    assert main(["show", "observers/recordings", "--body", str(generated / "profile.toml")]) == 1
    assert "--body and --repertoire go together" in capsys.readouterr().err


def test_the_pictures_larger_stooped_demonstrator_is_mapped_onto_maxs_size_and_rest(generated, pm, tmp_path,
                                                                                    monkeypatch):
    """docs/correspondence.md's picture on the project's own data: its Python block (run as written, on this
    module's generated data) makes Morris's wave larger and stooped; body-mapping maps the demonstrator's standing
    onto Max's hub and his rigid links onto Max's lengths, and ``likeme show`` draws it."""
    import re
    from pathlib import Path

    from likeme.cli import main
    from toolkit.observe import Observer, compose_observer
    from toolkit.recordings.profile import load_profile

    text = (Path(__file__).resolve().parents[3] / "docs" / "correspondence.md").read_text(encoding="utf-8")
    block = re.search(r"On the project's own data.*?```python\n(.*?)```", text, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(block.replace('"gen/', f'"{generated}/'), {})  # writes wave_stooped.csv here
    profile = load_profile(generated / "profile.toml")
    seen = profile.read(tmp_path / "wave_stooped.csv")
    mapped = {}
    for name in ("body-mapping", "none"):
        character = compose_observer(pm, profile, generated / "repertoire", correspondence=name)
        observer = Observer(character, profile.body, seen.fps)
        observer.watch(seen)
        mapped[name] = observer.loop.memory.positions
    rest = character.motor.rest_pose()
    hub = rest - rest[profile.body.root_index]  # Max's own hub, root-relative
    standing = slice(20, 30)  # the second of standing before the wave, after the rest has been seen
    plain = np.mean([pose_distance(p, hub) for p in mapped["none"][standing]])
    after = np.mean([pose_distance(p, hub) for p in mapped["body-mapping"][standing]])
    assert plain > 0.02 and after < 0.2 * plain  # the stoop and the size read as Max's own rest
    out = tmp_path / "picture.png"
    assert main(["show", "observers/recordings", "--body", str(generated / "profile.toml"), "--repertoire",
                 str(generated / "repertoire"), "--correspondence", "body-mapping", "--view", "correspondence",
                 "--set", f"recording={tmp_path / 'wave_stooped.csv'}", "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000
