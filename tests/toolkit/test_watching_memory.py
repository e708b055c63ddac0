"""Bounded working memory and guarded plugins in the watching loop (issue 21).

A live observer keeps only the rows it still needs (the segment under way, what the segmenter may still report, the
last ``keep`` seconds), with row numbers still counted from the stream's first frame, and gives the same
observations as one that keeps everything; a segment that never closes is cut every ``max_segment`` seconds. Every
plugin the loop calls is guarded, and what it returns is checked: ``likeme observe`` reports a misbehaving plugin
as one line, never a traceback.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from plugins.bench.data import make_data
from plugins.bench.memory import random_stream
from tests.conftest import _info
from toolkit import Motion, PluginError, create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.watching import ObservationLog, WatchingLoop

FPS = 30.0


@pytest.fixture(scope="module")
def pm_():
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture(scope="module")
def data(tmp_path_factory, pm_):
    return make_data(pm_, tmp_path_factory.mktemp("memory"), seed=5, streams=1, per_stream=2)


@pytest.fixture(scope="module")
def profile(data):
    return load_profile(data / "profile.toml")


@pytest.fixture(scope="module")
def stream(pm_):
    """A minute of Morris's random movements at 30 fps (world positions in Max's parts)."""
    return next(random_stream(pm_, FPS, seed=11, block=int(60 * FPS)))


@contextlib.contextmanager
def told_to_forget():
    """The rows working memory is told it no longer needs (ObservationLog.forget's argument), in the order told."""
    told, forget = [], ObservationLog.forget

    def recording(log, row):
        told.append(row)
        return forget(log, row)

    ObservationLog.forget = recording
    try:
        yield told
    finally:
        ObservationLog.forget = forget


@contextlib.contextmanager
def slack(rows: int):
    """ObservationLog.slack set to ``rows`` (0: drop what is not needed at once, so short streams are trimmed)."""
    before = ObservationLog.slack
    ObservationLog.slack = rows
    try:
        yield
    finally:
        ObservationLog.slack = before


def key(found):
    return [(o.segment.start, o.segment.end, o.movement, o.decided_at,
             None if o.match is None else round(o.match.confidence, 9)) for o in found]


def fed(observer, positions, cuts):
    observer.reset()
    out = []
    for a, b in zip([0, *cuts], [*cuts, len(positions)]):
        out.extend(observer.push_block(positions[a:b]))
    return out + observer.flush()


# -- the log ---------------------------------------------------------------------------------------------------


def test_a_log_drops_rows_it_is_told_it_no_longer_needs_and_keeps_counting_from_the_first():
    log = ObservationLog(("a", "b"), 10.0, capacity=4)
    poses = np.arange(60, dtype=float).reshape(10, 2, 3)
    with slack(0):
        log.extend(poses[:6], np.ones((6, 2), bool))
        log.forget(4)
        log.extend(poses[6:], np.ones((4, 2), bool))
    assert (log.offset, log.n) == (4, 10)
    np.testing.assert_array_equal(log.positions, poses[4:])
    np.testing.assert_array_equal(log.motion(5, 8).positions, poses[5:8])
    np.testing.assert_array_equal(log.since(6).positions, poses[6:6])  # a view holding none yet
    memory = log.since(6)
    memory.feed(9)
    np.testing.assert_array_equal(memory.positions, poses[6:9])
    with pytest.raises(ValueError, match="rows from 2 were dropped: working memory holds rows 4..10"):
        log.motion(2, 8)


def test_hidden_parts_hold_across_what_was_dropped():
    log = ObservationLog(("a",), 10.0, capacity=2)
    with slack(0):
        log.extend(np.ones((3, 1, 3)), np.ones((3, 1), bool))
        log.forget(3)
        log.extend(np.full((2, 1, 3), np.nan), np.zeros((2, 1), bool))
    assert log.offset == 2  # the newest row stays, whatever is forgotten
    np.testing.assert_array_equal(log.positions, np.ones((3, 1, 3)))  # held from the last row seen
    assert log.visible.tolist() == [[True], [False], [False]]


# -- the same observations -------------------------------------------------------------------------------------

PAIRINGS = [("hub-threshold", "path-search", {}), ("hub-threshold", "forward-model", {}),
            ("velocity-direction", "dtw", {"segmenter": {"level": "movement", "rest_speed": 0.2}}),
            ("ruptures", "dtw", {"segmenter": {"window": 8.0}}),
            ("hub-threshold", "dtw", {"correspondence": {"plugin": "body-mapping"}})]


@pytest.fixture(scope="module")
def observers(data, profile, pm_):
    out = {}
    for segmenter, matcher, extra in PAIRINGS:
        extra = {k: dict(v) for k, v in extra.items()}
        correspondence = extra.pop("correspondence", {}).get("plugin", "")
        character = compose_observer(pm_, profile, data / "repertoire", segmenter=segmenter, matcher=matcher,
                                     settings=extra, correspondence=correspondence)
        out[segmenter, matcher, correspondence] = character
    return out


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pairing=st.integers(0, len(PAIRINGS) - 1), start=st.integers(0, 600), length=st.integers(300, 1200),
       keep=st.sampled_from([0.5, 1.0, 3.0]), seed=st.integers(0, 2**16), hidden=st.booleans())
@example(pairing=2, start=128, length=300, keep=0.5, seed=1, hidden=False)  # velocity-direction back-dating an
# onset 16 frames, past what half a second kept, before it said so (holds_since)
@example(pairing=1, start=600, length=1185, keep=0.5, seed=547, hidden=True)  # CI, 3030ef8
def test_a_bounded_working_memory_gives_the_observations_an_unbounded_one_gives(observers, profile, stream, pairing,
                                                                                 start, length, keep, seed, hidden):
    """On generated streams (Morris's random movements with noise, a part lost for a while), in random packets:
    the same segments, movements, decision frames and confidences whether working memory keeps every row or only
    what it needs, and the bounded one really holds less."""
    segmenter, matcher, extra = PAIRINGS[pairing]
    correspondence = extra.get("correspondence", {}).get("plugin", "")
    character = observers[segmenter, matcher, correspondence]
    positions = stream[start : start + length].copy()
    rng = np.random.default_rng(seed)
    if hidden:
        a = int(rng.integers(0, len(positions) - 20))
        positions[a : a + 20, int(rng.integers(0, positions.shape[1]))] = np.nan
    cuts = np.sort(rng.choice(np.arange(1, len(positions)), size=8, replace=False)).tolist()
    whole = fed(Observer(character, profile.body, FPS, keep=None), positions, cuts)
    with slack(0), told_to_forget() as told:
        bounded = Observer(character, profile.body, FPS, keep=keep)
        got = fed(bounded, positions, cuts)
    assert key(got) == key(whole)
    held = bounded.memory.n - bounded.memory.offset
    needed = bounded.memory.n - told[-1]  # the rows from the oldest one still needed, as of the last packet
    assert 1 <= needed <= len(positions)
    assert held <= max(2 * needed, 1)  # never more than twice what it needs (ObservationLog.forget)


def test_a_segment_that_never_closes_is_cut_every_max_segment_seconds(data, profile, pm, scripted):
    """A demonstrator who never comes back to rest: the segment under way is cut every ``max_segment`` seconds
    (observations marked ``cut``, matched on their own frames), the rest reported from the last cut when it closes
    at last, and working memory stays bounded."""
    character = compose_observer(pm, profile, data / "repertoire", segmenter="scripted-cuts", matcher="early-commit",
                                 settings={"segmenter": {"cuts": [[5, 10**9]]}, "matcher": {"after": 3}})
    positions = next(random_stream(pm, FPS, seed=2, block=400))
    with slack(0):
        observer = Observer(character, profile.body, FPS, keep=0.5, max_segment=2.0)
        found, held = [], 0
        for a in range(0, 400, 7):
            found.extend(observer.push_block(positions[a : a + 7]))
            held = max(held, observer.memory.n - observer.memory.offset)
        found.extend(observer.flush())
    spans = [(o.segment.start, o.segment.end, o.cut) for o in found]
    starts = list(range(5, 365, 60))
    assert spans == [(s, s + 60, True) for s in starts] + [(365, 400, False)]
    assert all(o.movement == "jump" and o.decided_at == 3 for o in found)  # followed anew from each cut
    assert held <= 60 + 15 + 7


def test_without_keep_every_row_is_kept_and_nothing_is_cut(data, profile, pm_):
    character = compose_observer(pm_, profile, data / "repertoire")
    observer = Observer(character, profile.body, FPS, keep=None)
    positions = next(random_stream(pm_, FPS, seed=3, block=900))
    with slack(0):
        observer.push_block(positions)
    assert observer.memory.offset == 0 and len(observer.poses) == 900


def test_watch_keeps_the_whole_motion_for_views(data, profile, pm_):
    character = compose_observer(pm_, profile, data / "repertoire")
    observer = Observer(character, profile.body, FPS)
    motion = Motion(next(random_stream(pm_, FPS, seed=4, block=900)), FPS, profile.body.parts)
    with slack(0):
        observer.watch(motion)
    assert observer.memory.offset == 0 and len(observer.poses) == 900


@pytest.mark.parametrize("keep, max_segment, expected", [(float("nan"), 60.0, "keep = nan"),
                                                          (-1.0, 60.0, "keep = -1.0"),
                                                          (1.0, float("inf"), "max_segment = inf"),
                                                          (1.0, 0.0, "max_segment = 0")])
def test_bounds_are_finite_seconds(max_character, keep, max_segment, expected):
    from toolkit import ConfigError

    with pytest.raises(ConfigError, match=expected):
        WatchingLoop(max_character, keep=keep, max_segment=max_segment)


# -- guarded plugins -------------------------------------------------------------------------------------------


@pytest.fixture
def misbehaving(monkeypatch):
    """A plugin manager with the misbehaving fixture plugin, used by ``likeme`` in-process."""
    from tests.fixtures import misbehaving as module
    from likeme import cli

    pm = create_plugin_manager(autoload=False, trace=False)
    pm.register_plugin(module, _info("misbehaving"))
    monkeypatch.setattr(cli, "create_plugin_manager", lambda: pm)
    return pm


GUARDED = [
    (["--segmenter", "raising-segmenter"], "plugin 'raising-segmenter' failed in RaisingSegmenter.push_block: "
                                           "RuntimeError: the segmenter broke"),
    (["--segmenter", "far-segment"], "plugin 'far-segment' failed in FarSegment.push_block: returned a segment "
                                     "0..1000000000, which ends after the 21 frames seen, expected segments inside "
                                     "the stream"),
    (["--segmenter", "overlapping-segments"], "plugin 'overlapping-segments' failed in OverlappingSegments.flush: "
                                              "returned a segment 10..30 that begins before the end of the segment "
                                              "before it (20), expected ordered, disjoint segments"),
    (["--segmenter", "empty-segment"], "plugin 'empty-segment' failed in EmptySegment.push_block: returned an empty "
                                       "segment 0..0, expected 0 <= start < end"),
    (["--segmenter", "late-onset"], "plugin 'late-onset' failed in LateOnset.push_block: said a segment under way "
                                    "began at frame 25 after frame 20, expected a frame from 0 up to 20, or -1 for "
                                    "none"),
    (["--matcher", "bad-confidence"], "plugin 'bad-confidence' failed in BadConfidence.conclude: returned confidence "
                                      "nan for 'jump', expected a finite number in [0, 1]"),
    (["--matcher", "bad-confidence", "--set", 'matcher.confidence="5.0"'], "returned confidence 5.0 for 'jump', "
                                                                         "expected a finite number in [0, 1]"),
    (["--matcher", "stranger"], "plugin 'stranger' failed in Stranger.conclude: returned movement 'teleport', "
                                "expected a movement of the observer's repertoire or None (unknown); available: "),
    (["--matcher", "raising-matcher"], "plugin 'raising-matcher' failed in RaisingMatcher.conclude: "
                                       "ZeroDivisionError: division by zero"),
]


@pytest.mark.parametrize("args, expected", GUARDED)
def test_observe_reports_a_misbehaving_plugin_as_one_line(data, misbehaving, capsys, args, expected):
    from likeme.cli import main

    code = main(["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"), *args,
                 str(data / "streams" / "stream_1.bvh")])
    out = capsys.readouterr()
    assert code == 1
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("likeme: error: plugin "), out.err
    assert expected in lines[0]
    assert "Traceback" not in out.err + out.out


def test_a_perception_that_raises_is_named(data, profile, pm_, monkeypatch):
    character = compose_observer(pm_, profile, data / "repertoire")
    observer = Observer(character, profile.body, FPS)

    def broken(*args):
        raise KeyError("left_hand")

    monkeypatch.setattr(observer.perception, "perceive_poses", broken)
    with pytest.raises(PluginError, match=r"plugin 'motion-capture' failed in MotionCapture.perceive_poses: "
                                          r"KeyError: 'left_hand'"):
        observer.push(np.zeros((len(profile.body.parts), 3)))


@pytest.mark.parametrize("args, expected", [
    (["segmentation", "--segmenter", "raising-segmenter"], "likeme: error: plugin 'raising-segmenter' failed in "
                                                           "RaisingSegmenter.push_block: RuntimeError: the segmenter "
                                                           "broke"),
    (["stream", "--segmenter", "overlapping-segments", "--matcher", "dtw", "--repertoire", "REPERTOIRE"],
     "likeme: error: plugin 'overlapping-segments' failed in OverlappingSegments.flush: returned a segment 10..30"),
    (["recognition", "--matcher", "stranger", "--repertoire", "REPERTOIRE", "--demos", "DEMOS"],
     "likeme: error: plugin 'stranger' failed in Stranger.conclude: returned movement 'teleport'"),
])
def test_bench_reports_a_misbehaving_plugin_as_one_line(data, misbehaving, capsys, args, expected):
    from likeme.cli import main

    args = [str(data / "repertoire") if a == "REPERTOIRE" else str(data / "demos") if a == "DEMOS" else a
            for a in args]
    streams = [] if args[0] == "recognition" else ["--streams", str(data / "streams")]
    code = main(["bench", *args, "--body", str(data / "profile.toml"), *streams, "--quiet"])
    out = capsys.readouterr()
    assert code == 1
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(expected), out.err
    assert "Traceback" not in out.err + out.out


# -- the memory benchmark --------------------------------------------------------------------------------------


@pytest.mark.benchmark
def test_the_memory_benchmark_prints_flat_rows_held_and_observes_a_written_stream(capsys):
    """``likeme bench memory``: a line per simulated interval whose rows held stop growing once the stream is longer
    than what working memory keeps, and a ``likeme observe`` subprocess on a written stream that exits cleanly."""
    from likeme.cli import main

    assert main(["bench", "memory", "--minutes", "2", "--every", "0.5", "--fps", "30", "--block", "45",
                 "--observe-minutes", "0.2"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    table = [line.split() for line in lines[2:6]]
    assert [float(r[0]) for r in table] == [0.5, 1.0, 1.5, 2.0]
    assert [int(r[1]) for r in table] == [900, 1800, 2700, 3600]
    held = [int(r[3]) for r in table]
    assert held[-1] < 3600 // 2 and max(held) <= ObservationLog.slack + 10 * 30  # what is let go unused, and keep
    observed = next(line for line in lines if line.strip().startswith("0.2 "))
    assert observed.split()[4] == "0"  # the subprocess's exit status


def test_a_written_stream_is_read_back_at_its_length_and_rate(tmp_path, pm_, data, profile):
    from plugins.bench.memory import write_stream

    path = write_stream(pm_, tmp_path / "s.bvh", minutes=0.25, fps=60.0, seed=1)
    motion = profile.read(path)
    assert motion.n_frames == 900 and motion.fps == pytest.approx(60.0)
    assert np.isfinite(motion.positions).all()
