"""Rows given at once (``Matcher.replay``, issue 22; :meth:`ForwardModel.replay
<plugins.matchers.forward_model.matcher.ForwardModel.replay>`): the forward model's answers and state are those of the
rows fed one at a time.

When the watching loop gives a streaming matcher rows that are all in working memory already (a stroke matched on
its own frames after the segmenter split a movement, a segment whose onset was reported late), it calls
``replay(memory, stop)``. The base class feeds them one by one (``observe`` after each); the forward model skips the
rows after which nothing can happen: before any subsystem has moved ``min_move`` since the onset, and after the
segment settled. These tests hold it to the base class's row-by-row replay: on random windows of the project's
generated streams (hypothesis: the window, how many rows were fed one by one before, the matcher's settings), the
same answers with the same rows, the same ``inspect()``, the same conclusion and the same motor graph; and in the
watching loop, the same observations and states after every segment.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plugins.bench.data import make_data
from plugins.bench.mocap import _streams
from plugins.matchers.forward_model import ForwardModel
from tests.toolkit.test_watching_settled import frozen, watched
from toolkit import Match, Matcher, create_plugin_manager
from toolkit.errors import PluginError
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.watching import WatchingLoop

SETTINGS = ({}, {"threshold": 0.02}, {"threshold": 0.01, "learn": False}, {"together": False},
            {"min_move": 0.05})


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False, trace=False)


@pytest.fixture(scope="module")
def generated(tmp_path_factory, pm):
    data = make_data(pm, tmp_path_factory.mktemp("replay_block"), seed=5, streams=2, per_stream=4)
    profile = load_profile(data / "profile.toml")
    streams = [profile.read(path, None) for path, _ in _streams(data / "streams")]
    return data, profile, streams


@pytest.fixture(scope="module")
def logs(pm, generated):
    """Each stream's working memory as the watching loop perceived it (root-relative, in the observer's parts)."""
    data, profile, streams = generated
    character = compose_observer(pm, profile, data / "repertoire", segmenter="velocity-direction",
                                 matcher="forward-model")
    out = []
    for motion in streams:
        observer = Observer(character, profile.body, motion.fps)
        observer.watch(motion)
        out.append(observer.loop.memory)
    return out


@pytest.fixture(scope="module")
def pairs(pm, generated):
    """Per settings, two forward models composed alike: one replays row by row (the base class), one at once."""
    data, profile, _ = generated
    cache = {}

    def pair(i: int) -> tuple[ForwardModel, ForwardModel]:
        if i not in cache:
            cache[i] = tuple(compose_observer(pm, profile, data / "repertoire", segmenter="velocity-direction",
                                              matcher="forward-model", settings={"matcher": {"comparison": "strokes", **SETTINGS[i]}}).matcher
                             for _ in range(2))
        return cache[i]

    return pair


def state(matcher: ForwardModel) -> tuple:
    """What can be told of a forward model from outside: its ``inspect()``, whether and when it settled, and every
    subsystem's active node and edges."""
    motor = matcher.motor
    return (frozen(dict(matcher.inspect())), matcher.settled(),
            tuple((name, motor.active_node(name), tuple(sorted(e.name for e in motor.edges(name))))
                  for name in motor.subsystems))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                 HealthCheck.too_slow])
@given(which=st.integers(0, len(SETTINGS) - 1), stream=st.integers(0, 1), start=st.floats(0.0, 1.0),
       length=st.integers(1, 120), before=st.floats(0.0, 1.0), again=st.booleans())
def test_rows_given_at_once_are_the_rows_fed_one_by_one(pairs, logs, which, stream, start, length, before, again):
    """A window of a stream (anywhere, 1-120 rows), some of its rows first fed one by one (``observe``), the rest
    given by ``replay``: the forward model's answers (each with its row), its state after, its conclusion and its
    motor graph are those of the base class's replay (row by row). ``again``: the rest given in two calls."""
    plain, fast = pairs(which)
    log = logs[stream]
    first = int(start * (log.n - 1))
    stop = min(log.n, first + length)
    fed = first + int(before * (stop - first))
    results = []
    for matcher, replay in ((plain, Matcher.replay.__get__(plain)), (fast, fast.replay)):
        memory = log.since(first)
        matcher.begin(memory)
        answers = []
        for row in range(first, fed):
            memory.feed(row + 1)
            match = matcher.observe(memory)
            if match is not None:
                answers.append((row, match))
        middle = (fed + stop) // 2 if again else stop
        answers += replay(memory, middle) + replay(memory, stop)
        assert memory.n == stop - first
        shown = [(row, frozen((m.movement, m.confidence, m.decided_at, m.path, m.details))) for row, m in answers]
        during = state(matcher)
        concluded = matcher.conclude(log.motion(first, stop))
        results.append((shown, during, None if concluded is None else frozen(
            (concluded.movement, concluded.confidence, concluded.decided_at, concluded.path, concluded.details)),
            state(matcher)))
    assert results[1] == results[0]


@pytest.mark.parametrize("options", [{}, {"threshold": 0.1}, {"together": False, "threshold": 0.03}])
def test_the_watching_loop_gives_the_same_observations(pm, generated, monkeypatch, options):
    """Velocity-direction + the forward model on the generated streams, rows replayed at once and row by row: every
    observation, the matcher's state after every segment and every edge learned are the same, and fewer rows were
    observed one by one."""
    data, profile, streams = generated
    runs, observed = [], []
    for at_once in (False, True):
        character = compose_observer(pm, profile, data / "repertoire", segmenter="velocity-direction",
                                     matcher="forward-model", settings={"matcher": {"comparison": "strokes", **options}})
        calls = [0]
        observe = ForwardModel.observe

        def counted(self, memory, _calls=calls):
            _calls[0] += 1
            return observe(self, memory)

        with monkeypatch.context() as m:
            m.setattr(ForwardModel, "observe", counted)
            if not at_once:
                m.setattr(ForwardModel, "replay", Matcher.replay)
            runs.append(watched(character, profile, streams, monkeypatch, True))
        observed.append(calls[0])
    assert runs[1][:3] == runs[0][:3]
    assert any(o[4] is not None and o[4][0] is not None for o in runs[0][0])
    assert observed[1] < observed[0]


class _Replays(Matcher):
    """A streaming matcher whose ``replay`` answers as ``answer`` says (for the watching loop's checks)."""

    name = "replays"
    streaming = True

    def __init__(self, answer):
        self.answer = answer

    def match(self, motion):
        return Match.unknown()

    def replay(self, memory, stop):
        return self.answer(memory, stop)


@pytest.mark.parametrize("answer, message", [
    (lambda memory, stop: 3, "returned 3, expected [(row, Match), ...]"),
    (lambda memory, stop: [], "rows of the segment"),
])
def test_a_replay_that_breaks_its_contract_is_a_plugin_error(answer, message):
    """The watching loop checks what ``replay`` returns (pairs of a row and a match) and that every row up to the
    stop was given; else a :class:`PluginError` naming the matcher and the method."""
    loop = WatchingLoop.__new__(WatchingLoop)
    matcher = _Replays(answer)

    class Character:
        pass

    loop.character = Character()
    loop.character.matcher = matcher
    loop._direct = True
    from toolkit.watching import ObservationLog

    log = ObservationLog(("a",), 30.0)
    log.extend(np.zeros((5, 1, 3)), np.ones((5, 1), dtype=bool))
    loop._view = log.since(0)
    with pytest.raises(PluginError, match="replay") as error:
        loop._replay(5)
    assert message in str(error.value)
