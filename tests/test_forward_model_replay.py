"""After a deviation the forward model predicts the rest again from the last correct node (Fig. 3) and replays the
rows seen since through a new track. The replay follows that track incrementally (its rows gathered once each, its
path lengths by :class:`~plugins.matchers.forward_model._Walk`); these tests compare it with the replay that
gathers the rows and sums their path lengths whole at every row (the previous way), on Fig. 3's games."""

from __future__ import annotations

import pytest

from plugins.matchers.forward_model import ForwardModel
from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, hookimpl, load_scenario


def both_ways(play, *args):
    """``play(monkeypatch, *args, on)`` with a shortcut on, then off, each under a monkeypatch of its own."""
    out = []
    for on in (True, False):
        with pytest.MonkeyPatch.context() as monkeypatch:
            out.append(play(monkeypatch, *args, on))
    return tuple(out)


def play_fig3_games(snapshot):
    """Fig. 3's games played once: every answer Max gives, and ``snapshot(view)`` of the forward model's
    ``inspect()`` after each world step in which it holds a segment."""

    class Traces:
        def __init__(self) -> None:
            self.seen: list = []

        @hookimpl
        def likeme_world_stepped(self, world):
            matcher = world.actors["max"].character.matcher
            if matcher._memory is not None:
                self.seen.append(snapshot(matcher.inspect()))

    pm = create_plugin_manager(autoload=False)
    traces = Traces()
    pm.register(traces, name="traces")
    world = load_scenario(CHARACTERS / "scenarios" / "fig3_games.toml", pm).run()
    matches = [(m.movement, m.confidence, m.decided_at, m.path, repr(m.details))
               for m in (e.data["match"] for e in world.events_of("movement_recognised", "max"))]
    return matches, traces.seen


def _play(monkeypatch, incremental: bool):
    used = []
    leading = ForwardModel._leading

    def counted(self, memory):
        answer = leading(self, memory) if incremental else False
        used.append(answer)
        return answer

    monkeypatch.setattr(ForwardModel, "_leading", counted)

    matches, seen = play_fig3_games(lambda view: (view["frames"], view["trace"], view["committed"],
                                                  view["committed_path"], view["committed_at"], view["deviated_at"]))
    return matches, seen, used


@pytest.fixture(scope="module")
def plays():
    return both_ways(_play)  # incremental, then whole


def test_the_replay_follows_the_new_track_incrementally(plays):
    (_, _, used), _ = plays
    assert any(used)  # replayed rows were a leading view of the working memory, kept and walked


def test_the_incremental_replay_gives_the_same_answers_and_traces_to_the_bit(plays):
    (matches, seen, _), (matches_whole, seen_whole, _) = plays
    assert any(m[4].find("deviated") >= 0 for m in matches)  # a deviation was predicted again
    assert matches == matches_whole
    assert seen == seen_whole
