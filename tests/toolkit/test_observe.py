"""Watching motion-capture files: clip repertoires, the observe loop, the baselines and the mocap benchmarks.

Everything runs on data the project writes itself (``likeme bench make-data``: Max's movements as the
repertoire, Morris's as demos and streams, as BVH); the Bandai-Namco tests skip where the data is absent.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.clip_repertoire import load_clip_repertoire
from plugins.matchers.dtw import frame_distance
from plugins.bench.metrics import segmentation_scores
from plugins.bench.data import make_data
from toolkit.recordings.segments import read_segments
from plugins.bench.mocap import recognition
from tests.conftest import BANDAI, CHARACTERS
from toolkit import ConfigError, Motion, create_plugin_manager, load_character
from likeme.cli import main
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.watching import feed


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("generated"), seed=3, streams=3, per_stream=5)


@pytest.fixture(scope="module")
def profile(data):
    return load_profile(data / "profile.toml")


def test_the_hub_is_found_from_the_clips_and_is_maxs_standing_pose(data, profile, pm):
    repertoire = load_clip_repertoire(data / "repertoire", profile)
    max_c = load_character(CHARACTERS / "max.toml", pm)
    stand = max_c.motor.rest_pose()
    root = max_c.body.root_index
    assert len(repertoire.hubs) == 1  # every one of Max's movements starts and ends standing
    hub = repertoire.hubs[0]
    np.testing.assert_allclose(hub - hub[root], stand - stand[root], atol=1e-3)
    assert repertoire.movements == sorted(max_c.motor.movements())


def test_the_same_clips_become_a_posegraph_and_a_motor_command_graph(data, profile, pm):
    graph = compose_observer(pm, profile, data / "repertoire", matcher="path-search").motor
    commands = compose_observer(pm, profile, data / "repertoire", matcher="forward-model").motor
    assert graph.name == "posegraph" and commands.name == "motor-command-graph"
    assert sorted(graph.movements()) == sorted(commands.movements()) == load_clip_repertoire(
        data / "repertoire", profile).movements
    assert list(commands.subsystems) == ["body"]
    sequence = commands.sequences["jump"]
    assert commands.edge(sequence[0]).source == "hub" and commands.label("jump") == "jump"
    assert graph.perform("jump", fps=30).n_frames > 10 and commands.perform("jump", fps=30).n_frames > 10


def test_a_path_is_the_labelled_movement_it_follows_first_and_longest(data, profile, pm):
    motor = compose_observer(pm, profile, data / "repertoire", matcher="forward-model").motor
    bow, nod = motor.sequences["bow"], motor.sequences["nod"]
    assert len(bow) >= 2  # out to the bow, back from it (the hold between them cuts the clip)
    assert motor.label_of_path(tuple(bow)) == motor.label_of_path((bow[0],)) == "bow"
    assert motor.label_of_path((*bow, nod[0])) == "bow"  # the whole bow, then on into a nod
    assert motor.label_of_path((bow[0], nod[-1])) == "bow"  # leaves the bow for the nod's last edge
    motor.add_sequence([bow[0], nod[-1]])  # an unlabelled sequence (a commitment) does not veto the label
    assert motor.label_of_path((bow[0], nod[-1])) == "bow"
    motor.add_sequence([bow[0]], name="bow-like", label="curtsy")  # another movement with the same first edge
    assert motor.label_of_path((bow[0],)) is None and motor.label_of_path(tuple(bow[:2])) == "bow"
    assert motor.label_of_path(("no-such-edge",)) is None


def test_observing_a_stream_finds_and_names_its_movements(data, profile, pm):
    character = compose_observer(pm, profile, data / "repertoire", matcher="path-search")
    tp = found_n = true_n = right = 0
    for path in sorted((data / "streams").glob("*.bvh")):
        truth = read_segments(path.with_suffix(".segments.csv"))
        motion = profile.read(path)
        found = Observer(character, profile.body, motion.fps).watch(motion)
        scores = segmentation_scores([(o.segment.start, o.segment.end) for o in found], [(a, b) for a, b, _ in truth])
        tp, found_n, true_n = tp + scores["true_positives"], found_n + scores["found"], true_n + scores["true"]
        right += sum(o.movement == label for o, (_, _, label) in zip(found, truth))
    assert tp / found_n >= 0.9 and tp / true_n >= 0.75  # movements with a short pause between them may merge
    assert right >= 0.6 * true_n


def test_a_live_loop_gives_what_watching_the_whole_file_gives(data, profile, pm):
    character = compose_observer(pm, profile, data / "repertoire", segmenter="hub-threshold", matcher="dtw")
    path = data / "streams" / "stream_1.bvh"
    motion = profile.read(path)
    whole = Observer(character, profile.body, motion.fps).watch(motion)
    live = Observer(character, profile.body, motion.fps)
    got = []
    for f in range(motion.n_frames):
        got.extend(live.push(motion.positions[f]))
    got.extend(live.flush())
    assert [(o.segment, o.movement) for o in got] == [(o.segment, o.movement) for o in whole]


@pytest.mark.parametrize("segmenter, matcher", [("hub-threshold", "path-search"), ("hub-threshold", "forward-model"),
                                               ("velocity-direction", "dtw")])
def test_blocks_of_frames_give_what_frame_by_frame_gives(data, profile, segmenter, matcher):
    """Observer.push_block (a packet of frames, perceived and segmented at once) answers the same segments with
    the same movements at the same decision frames as push, frame by frame, whatever the packet sizes: for a
    vectorised perception and segmenter and for ones that use the frame-by-frame defaults, with a streaming
    matcher that commits early (forward-model) and batch matchers."""
    pm = create_plugin_manager(autoload=False, trace=False)
    # (velocity-direction: above the speed the stream's 3 mm noise gives the fastest of the parts)
    settings = {"segmenter": {"level": "movement", "rest_speed": 0.2}} if segmenter == "velocity-direction" else {}
    character = compose_observer(pm, profile, data / "repertoire", segmenter=segmenter, matcher=matcher,
                                 settings=settings)
    motion = profile.read(data / "streams" / "stream_2.bvh")
    positions = motion.positions.copy()
    positions[40:52, 3] = np.nan  # a part lost for a while
    observer = Observer(character, profile.body, motion.fps)

    def key(found):
        return [(o.segment.start, o.segment.end, o.movement, o.decided_at) for o in found]

    one = []
    for f in range(motion.n_frames):
        one.extend(observer.push(positions[f]))
    one.extend(observer.flush())
    assert len(one) >= 3
    rng = np.random.default_rng(0)
    for _ in range(3):
        observer.reset()
        cuts = np.sort(rng.choice(np.arange(1, motion.n_frames), size=12, replace=False))
        blocks = []
        for a, b in zip([0, *cuts], [*cuts, motion.n_frames]):
            blocks.extend(observer.push_block(positions[a:b]))
        blocks.extend(observer.flush())
        assert key(blocks) == key(one)
    observer.reset()
    whole = observer.push_block(positions) + observer.flush()
    assert key(whole) == key(one)
    np.testing.assert_array_equal(observer.visible[40:52, 3], False)


def test_nan_frames_and_hidden_parts_are_not_seen_rather_than_a_crash(data, profile, pm):
    character = compose_observer(pm, profile, data / "repertoire", matcher="path-search")
    motion = profile.read(data / "streams" / "stream_1.bvh")
    positions = motion.positions.copy()
    positions[50:80] = np.nan  # everything gone for a second
    positions[:, 2] = np.inf  # one part never finite
    observer = Observer(character, profile.body, motion.fps)
    found = []
    for f in range(len(positions)):
        found.extend(observer.push(positions[f]))
    found.extend(observer.flush())
    assert all(o.movement is None or o.movement in character.motor.movements() for o in found)
    assert found and all(a.segment.end <= b.segment.start for a, b in zip(found, found[1:]))


def test_the_forward_model_commits_before_a_familiar_demo_ends(data, profile, pm):
    character = compose_observer(pm, profile, data / "repertoire", matcher="forward-model")
    motion = profile.read(data / "repertoire" / "jump" / "max.bvh")  # his own jump, watched
    obs = Observer(character, profile.body, motion.fps).classify(motion)
    assert obs.movement == "jump"
    assert obs.decision_fraction < 1.0


STROKES = {"matcher": {"comparison": "strokes"}}
"""The paper's forward model (K&G §4.4: guiding strokes, drop-out at a threshold in metres)."""


def test_every_clip_is_watched_from_the_hub_whatever_came_before(data, profile, pm):
    """Observer.reset puts the motor system back at rest: the forward model's candidates are the hub's edges for
    every clip, so a clip's answer does not depend on the clips classified before it."""
    character = compose_observer(pm, profile, data / "repertoire", matcher="forward-model", settings=STROKES)
    observer = Observer(character, profile.body, 30.0)
    nod = profile.read(data / "demos" / "nod" / "morris_1.0.bvh")
    alone = observer.classify(nod)
    motor = character.motor
    motor.move_to("body", motor.edge(motor.sequences["bow"][0]).target)  # as a clip that ended half-way leaves it
    again = observer.classify(nod)
    assert character.matcher.inspect()["start_node"] == "hub"
    assert (again.movement, again.decided_at) == (alone.movement, alone.decided_at) == ("nod", alone.decided_at)


def test_a_demonstration_watched_from_a_few_frames_in_is_still_predicted(data, profile, pm):
    """A segment often begins after its movement did (a hub threshold is crossed once the body has left the hub):
    each part is predicted from the point of its stroke nearest to where it was first seen, so the forward model
    still commits early. Predicted from the strokes' starts, every candidate dropped out at once."""
    character = compose_observer(pm, profile, data / "repertoire", matcher="forward-model", settings=STROKES)
    observer = Observer(character, profile.body, 30.0)
    for movement in ("salute", "stretch", "jump"):
        motion = profile.read(data / "demos" / movement / "morris_1.0.bvh")
        for late in (0, 3):
            cut = Motion(motion.positions[late:], motion.fps, motion.parts, motion.visible[late:])
            obs = observer.classify(cut)
            assert obs.movement == movement and obs.decision_fraction < 0.5, (movement, late, obs)
        signals = character.matcher.inspect()
        assert signals["anchors"][signals["committed_path"][0]].max() > 0.01


def test_a_movement_begun_at_the_hub_is_followed_from_the_hub_wherever_the_last_one_left_off(data, profile, pm):
    """Within a stream the forward model's active node is where the last movement it followed ended; one that
    ended away from it (a posture that differs at the end) must not make the next, begun at the hub, unreadable."""
    character = compose_observer(pm, profile, data / "repertoire", matcher="forward-model", settings=STROKES)
    motor, matcher = character.motor, character.matcher
    nod = profile.read(data / "demos" / "nod" / "morris_1.0.bvh")
    elsewhere = motor.edge(motor.sequences["bow"][0]).target
    observer = Observer(character, profile.body, nod.fps)
    motor.move_to("body", elsewhere)  # as an earlier segment of the stream left it
    percepts = [observer.perception.perceive_pose(nod.positions[f], None, profile.body, f / nod.fps)
                for f in range(nod.n_frames)]
    seen = Motion(np.stack([p.pose for p in percepts]), nod.fps, profile.body.parts, np.stack([p.visible for p in percepts]))
    early = next((m for m in feed(matcher, seen) if m is not None), None)
    assert matcher.inspect()["start_node"] == "hub" and early is not None and early.movement == "nod"


@settings(max_examples=30, deadline=None)
@given(st.integers(5, 30), st.integers(1, 6), st.floats(0.01, 1.0), st.integers(0, 2**16))
def test_the_dtw_distance_per_frame_does_not_shrink_with_length(n, k, offset, seed):
    """The same series at any length is at the same distance from the same template (the distance used to be
    divided by the length after the root, so the longest template came out nearest to everything)."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n, 6))
    shift = np.full(6, offset / np.sqrt(6))
    base = frame_distance(x, x + shift)
    long = frame_distance(np.repeat(x, k, axis=0), np.repeat(x + shift, k, axis=0))
    assert long == pytest.approx(base, rel=1e-6)
    assert base == pytest.approx(offset / np.sqrt(2), rel=1e-6)


def test_recognition_scores_every_matcher_on_the_same_demos(data, profile, pm):
    result = recognition(pm, profile, data / "repertoire", data / "demos", ["path-search", "dtw"])
    rows = {r["plugin"]: r for r in result["plugins"]}
    assert rows["path-search"]["accuracy"] >= 0.85 and rows["dtw"]["accuracy"] >= 0.85
    assert rows["dtw"]["decision_median"] == 1.0  # dtw waits for the end
    assert len(result["items"]) == 2 * rows["dtw"]["items"]
    m = np.array(rows["dtw"]["confusion"])
    assert m.sum() == rows["dtw"]["items"] and np.trace(m) == round(rows["dtw"]["accuracy"] * m.sum())


@pytest.mark.benchmark
def test_the_bench_commands_print_tables_and_write_json_csv_and_png(data, tmp_path, capsys):
    common = ["--body", str(data / "profile.toml"), "--quiet"]
    out = tmp_path / "out"
    out.mkdir()
    assert main(["bench", "segmentation", *common, "--streams", str(data / "streams"), "--json", str(out / "s.json"),
                 "--csv", str(out / "s.csv"), "--plot", str(out / "s.png")]) == 0
    text = capsys.readouterr().out
    assert "| hub-threshold |" in text and "| ruptures |" in text and "| velocity-direction |" in text
    result = json.loads((out / "s.json").read_text())
    hub = next(r for r in result["plugins"] if r["plugin"] == "hub-threshold")
    assert hub["f1"] >= 0.9
    assert result["settings"]["versions"]["ruptures"] != "not installed"
    csv_lines = (out / "s.csv").read_text().splitlines()
    assert csv_lines[0].startswith("kind,plugin,item") and sum(line.startswith("item,") for line in csv_lines) == 9
    assert (out / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["bench", "stream", *common, "--repertoire", str(data / "repertoire"), "--streams",
                 str(data / "streams"), "--segmenter", "hub-threshold", "--matcher", "dtw",
                 "--json", str(out / "t.json")]) == 0
    rate = json.loads((out / "t.json").read_text())["plugins"][0]["error_rate"]
    assert rate <= 0.2
    assert main(["bench", "recognition", *common, "--repertoire", str(data / "repertoire"), "--demos",
                 str(data / "demos"), "--matcher", "dtw", "--plot", str(out / "r.png")]) == 0
    assert "dtw confusion" in capsys.readouterr().out and (out / "r.png").stat().st_size > 1000


def test_observe_prints_segments_and_json(data, capsys):
    args = ["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
            str(data / "streams" / "stream_2.bvh")]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "stream_2.bvh: " in text and "decided at frame" in text
    assert main([*args, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    truth = [m for _, _, m in read_segments(data / "streams" / "stream_2.segments.csv")]
    assert [s["movement"] for s in report[0]["segments"]][: len(truth)].count("unknown") <= 1
    assert {"start_frame", "end_frame", "start_s", "end_s", "confidence", "decision_fraction"} <= set(
        report[0]["segments"][0])
    # why each segment ends, as the segmenter said (Segment.reason): hub-threshold's hub, or the stream's end
    ends = [s["ends"] for s in report[0]["segments"]]
    assert ends and set(ends) <= {"back near a hub pose", "came to rest", "the stream ended"}
    assert text.count("\n    ends: ") == len(ends)
    assert "no movement:" not in text


def test_observe_says_how_the_segmenter_begins_a_movement_where_a_recording_gave_none(data, capsys):
    """A demonstrator who never leaves the rest (Morris standing) gives hub-threshold no segment: the file's line
    says 0 segments, and what the segmenter waits for and what to try instead follow it."""
    stand = sorted((data / "demos" / "stand").glob("*.bvh"))[0]
    assert main(["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
                 str(stand)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith(", 0 segments")
    assert lines[1].startswith("  no movement: hub-threshold begins a movement where the body leaves its rest")
    assert "--segmenter velocity-direction" in lines[1]


@pytest.mark.parametrize(
    "args, expected",
    [
        (["--matcher", "forward-mode"], "unknown matcher 'forward-mode'; expected the name of a registered matcher; "
                                        "available: dtw, forward-model, path-search"),
        (["--segmenter", "rupture"], "unknown segmenter 'rupture'"),
        (["--set", "perception.plugin=synthetic-vision"], "perception 'synthetic-vision' cannot watch recorded poses; "
                                                          "expected a perception that implements perceive_pose; "
                                                          "available: motion-capture"),
    ],
)
def test_observe_refuses_unknown_plugins_with_the_registered_names(data, capsys, args, expected):
    assert main(["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"), *args,
                 str(data / "streams" / "stream_1.bvh")]) == 1
    assert expected in capsys.readouterr().err


def test_bad_segment_files_and_clip_folders_are_named(tmp_path, profile):
    bad = tmp_path / "s.segments.csv"
    bad.write_text("start,end,movement\n0,10,a\n")
    with pytest.raises(ConfigError, match=r"s.segments.csv:1: found header .*expected the header start_frame"):
        read_segments(bad)
    bad.write_text("start_frame,end_frame,movement\n0,10,a\n12,x,b\n")
    with pytest.raises(ConfigError, match=r"s.segments.csv:3: found '12,x,b'; expected two frame numbers"):
        read_segments(bad)
    bad.write_text("start_frame,end_frame,movement\n10,10,a\n")
    with pytest.raises(ConfigError, match=r":2: segment 10..10; expected 0 <= start_frame < end_frame"):
        read_segments(bad)
    (tmp_path / "empty").mkdir()
    with pytest.raises(ConfigError, match="empty: no clips found"):
        load_clip_repertoire(tmp_path / "empty", profile)


@pytest.mark.skipif(not BANDAI.is_dir(), reason=f"Bandai-Namco motion capture not found at {BANDAI}")
def test_observing_a_bandai_namco_clip(tmp_path, pm):
    for style in ("normal", "happy"):
        for content in ("bow", "bye"):
            folder = tmp_path / style / content
            folder.mkdir(parents=True)
            (folder / "clip.bvh").symlink_to(BANDAI / f"dataset-1_{content}_{style}_001.bvh")
    profile = load_profile(CHARACTERS / "profiles" / "bandai-namco.toml")
    rows = {r["plugin"]: r for r in recognition(pm, profile, tmp_path / "normal", tmp_path / "happy",
                                                 ["path-search", "dtw"])["plugins"]}
    assert rows["dtw"]["items"] == 2 and rows["dtw"]["accuracy"] == 1.0


def test_a_clip_built_motor_command_graph_saves_and_loads_its_labels_without_doubling_edges(data, profile, pm):
    commands = compose_observer(pm, profile, data / "repertoire", matcher="forward-model").motor
    state = json.loads(json.dumps(commands.get_state()))
    again = compose_observer(pm, profile, data / "repertoire", matcher="forward-model").motor

    def by_name(s):  # edges in name order, stroke numbers to 5 decimals (a stroke's normal is normalised on load)
        body = dict(s["body"])
        body["edges"] = [{**e, "commands": [{k: np.round(v, 5).tolist() if isinstance(v, list | float) else v
                                            for k, v in stroke.items()} for stroke in e["commands"]]}
                         for e in sorted(body["edges"], key=lambda e: e["name"])]
        return body

    again.set_state(state)  # onto a graph the same clips built: the same commands, not twice as many
    assert by_name(again.get_state()) == by_name(state)
    assert again.graphs["body"].number_of_edges() == commands.graphs["body"].number_of_edges()
    unlabelled = compose_observer(pm, profile, data / "repertoire", matcher="forward-model").motor
    unlabelled.labels.clear()
    assert sorted(unlabelled.movements()) != sorted(commands.movements())  # example names, not movements
    unlabelled.set_state(state)  # the labels come back with the state
    assert unlabelled.labels == commands.labels and sorted(unlabelled.movements()) == sorted(commands.movements())


# the head of the observer templates the tests below write: a motor system and perception, as the recordings template
MINE = """
        [observer]
        name = "mine"
        [motor]
        plugin = "posegraph"
        [perception]
        plugin = "motion-capture"
"""


def test_an_observer_takes_what_it_is_not_told_from_the_observer_template(data, profile, pm, write, capsys):
    default = compose_observer(pm, profile, data / "repertoire")
    assert [default.perception.name, default.segmenter.name, default.matcher.name, default.motor.name] == [
        "motion-capture", "hub-threshold", "path-search", "posegraph"]  # characters/observers/recordings.toml
    mine = write("mine.toml", MINE + """
        [segmenter]
        plugin = "velocity-direction"
        level = "movement"
        [matcher]
        plugin = "dtw"
        """)
    observer = compose_observer(pm, profile, data / "repertoire", template=mine)
    assert observer.segmenter.name == "velocity-direction" and observer.segmenter.params["level"] == "movement"
    assert observer.matcher.name == "dtw"
    follows = compose_observer(pm, profile, data / "repertoire", matcher="forward-model")
    assert follows.motor.name == "motor-command-graph" and follows.matcher.params["learn"] is False
    assert compose_observer(pm, profile, data / "repertoire", matcher=None).matcher is None
    assert main(["validate", str(mine)]) == 0
    assert "observer template: motor posegraph, perception motion-capture, segmenter velocity-direction" in \
        capsys.readouterr().out
    write("bad.toml", '[observer]\nname = "bad"\n[matcher]\nplugin = "dtw"\nwindow = 2.0\n')
    with pytest.raises(ConfigError, match=r"bad.toml:5: key matcher.window: value 2.0 out of range"):
        compose_observer(pm, profile, data / "repertoire", template=mine.parent / "bad.toml")


def test_a_plugin_named_instead_takes_its_own_table_of_the_template(data, profile, pm, write):
    """`[segmenters.NAME]`: the parameters NAME gets when a command names it instead of the template's own plugin
    (the recordings template cuts whole movements with velocity-direction, not strokes); a table for a plugin that is
    not named changes nothing, and `--set` still wins."""
    from toolkit.config.search import resolve_file
    from toolkit.config.toml import read_toml

    own = read_toml(resolve_file("observers/recordings.toml", None, pm))["segmenters"]["velocity-direction"]
    named = compose_observer(pm, profile, data / "repertoire", segmenter="velocity-direction")
    assert own["level"] == "movement" and all(named.segmenter.declared[k] == v for k, v in own.items())
    assert compose_observer(pm, profile, data / "repertoire").segmenter.name == "hub-threshold"
    stroke = compose_observer(pm, profile, data / "repertoire", segmenter="velocity-direction",
                              settings={"segmenter": {"level": "stroke"}})
    assert stroke.segmenter.params["level"] == "stroke" and stroke.segmenter.params["units"] == own["units"]
    mine = write("alternatives.toml", MINE + """
        [segmenter]
        plugin = "hub-threshold"
        [matcher]
        plugin = "path-search"
        [matchers.dtw]
        window = 0.25
        [motors.motor-command-graph.strokes]
        drop = 0.4
        """)
    dtw = compose_observer(pm, profile, data / "repertoire", matcher="dtw", template=mine)
    assert dtw.matcher.params["window"] == 0.25
    assert compose_observer(pm, profile, data / "repertoire", template=mine).matcher.name == "path-search"
    follows = compose_observer(pm, profile, data / "repertoire", matcher="forward-model", template=mine)
    assert follows.motor.name == "motor-command-graph" and follows.motor.params["strokes"] == {"drop": 0.4,
                                                                                                "angle": 50.0}


def test_naming_the_templates_own_matcher_keeps_its_parameters_and_another_starts_afresh(data, profile, pm):
    """The observer template sets path-search's parameters for recordings; `--matcher path-search` must not drop
    them (it did: every benchmark that named the matcher ran the plugin's defaults), `--matcher dtw` gets dtw's."""
    from toolkit.config.search import resolve_file
    from toolkit.config.toml import read_toml

    template = read_toml(resolve_file("observers/recordings.toml", None, pm))["matcher"]
    named = compose_observer(pm, profile, data / "repertoire", matcher="path-search")
    assert template["plugin"] == "path-search" and len(template) > 1
    assert all(named.matcher.declared[k] == v for k, v in template.items() if k != "plugin")
    other = compose_observer(pm, profile, data / "repertoire", matcher="dtw")
    assert other.matcher.name == "dtw" and other.matcher.params == other.matcher.declared


def test_the_profile_given_is_the_one_used_and_a_folder_is_read_once_per_settings(data, profile, pm, tmp_path):
    """Objects, not paths: compose_observer hands the motor system the profile object it was given (a profile whose
    file is gone composes as well), and one ClipFolder given to several observers is read once per motor settings."""
    import shutil

    from toolkit.recordings.clips import ClipFolder

    moved = tmp_path / "profile.toml"
    shutil.copy(data / "profile.toml", moved)
    gone = load_profile(moved)
    moved.unlink()  # nothing may read the profile again from its file
    first = compose_observer(pm, gone, data / "repertoire")
    assert first.repertoire.profile is gone and first.motor.clips.profile is gone
    folder = ClipFolder(data / "repertoire", profile)
    a, b = compose_observer(pm, profile, folder), compose_observer(pm, profile, folder, matcher="dtw")
    wider = compose_observer(pm, profile, folder, settings={"motor": {"hub_radius": 0.2}})
    assert a.motor.clips is b.motor.clips and wider.motor.clips is not a.motor.clips
    assert len(folder.read) == 2 and wider.motor.clips.hub_radius == 0.2
    np.testing.assert_array_equal(a.motor.clips.hubs, first.motor.clips.hubs)
