"""Fixture plugin: records every run-event hook call as (hook name, kwargs)."""

from __future__ import annotations

from toolkit import hookimpl


class Recorder:
    def __init__(self) -> None:
        self.calls: list[tuple[str, dict]] = []

    def names(self) -> list[str]:
        return [name for name, _ in self.calls]

    @hookimpl
    def likeme_movement_started(self, world, actor, request):
        self.calls.append(("movement_started", {"actor": actor.id, "movement": request.movement,
                                                "imitating": request.imitating}))

    @hookimpl
    def likeme_target_perceived(self, world, observer, target, percept):
        self.calls.append(("target_perceived", {"observer": observer.id, "target": target.id, "frame": world.frame,
                                                "seen": int(percept.visible.sum())}))

    @hookimpl
    def likeme_segment_found(self, world, observer, target, segment):
        self.calls.append(("segment_found", {"observer": observer.id, "target": target.id, "segment": segment}))

    @hookimpl
    def likeme_movement_recognised(self, world, observer, target, segment, match):
        self.calls.append(("movement_recognised", {"observer": observer.id, "segment": segment, "match": match}))

    @hookimpl
    def likeme_movement_learned(self, character, movement, details):
        self.calls.append(("movement_learned", {"character": character.name, "movement": movement, **details}))

    @hookimpl
    def likeme_behaviour_identified(self, world, observer, target, behaviour):
        self.calls.append(("behaviour_identified", {"observer": observer.id, "behaviour": behaviour}))

    @hookimpl
    def likeme_imitation_started(self, world, actor, target, request):
        self.calls.append(("imitation_started", {"actor": actor.id, "target": target.id, "movement": request.movement}))

    @hookimpl
    def likeme_imitation_stopped(self, world, actor, target, movement, reason):
        self.calls.append(("imitation_stopped", {"actor": actor.id, "movement": movement, "reason": reason}))

    @hookimpl
    def likeme_world_stepped(self, world):
        self.calls.append(("world_stepped", {"frame": world.frame}))

    @hookimpl
    def likeme_character_composed(self, character):
        self.calls.append(("character_composed", {"character": character.name}))
