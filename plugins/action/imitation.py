"""Action system ``imitation``: imitate a recognised movement by performing one's own.

Buchsbaum & Blumberg 2005, §5.3: once Max has identified Morris's movement as
one of his own, his action system requests *that* movement from his motor
system; he does not replay the observed path. Here every recognised movement
with enough confidence is imitated (queued if the character is busy).

Kopp & Graeser 2006, §4.4: a familiar movement demonstrated at another speed
re-parameterises the command in speed. When the matcher measured the
demonstration's speed relative to the command (``details["speed"]``, the
``forward-model`` does), the imitation is performed at that speed.
"""

from __future__ import annotations

from toolkit import ActionSystem, MovementRequest, Parameter, hookimpl


class Imitation(ActionSystem):
    """Performs its own version of every movement it recognises (§5.3)."""

    name = "imitation"
    parameters = (
        Parameter("min_confidence", float, 0.0, "Imitate only matches at least this confident.", minimum=0.0, maximum=1.0),
        Parameter("speed", float, 1.0, "Playback speed of the imitation (times the demonstrator's, with follow_speed).",
                  minimum=0.01),
        Parameter("follow_speed", bool, True, "Perform at the speed the matcher measured in the demonstration "
                  "(a familiar movement at another speed, K&G §4.4)."),
    )

    def respond(self, actor, target, match, behaviour, world) -> MovementRequest | None:
        if not match.known or match.confidence < self.params["min_confidence"]:
            return None
        if match.movement not in actor.character.motor.movements():
            return None
        measured = float(match.details.get("speed", 1.0)) if self.params["follow_speed"] else 1.0
        return MovementRequest(
            match.movement,
            speed=self.params["speed"] * measured,
            reason=f"imitating {target.id}'s {match.movement}",
            imitating=target.id,
        )


@hookimpl
def likeme_register_action_systems():
    return [Imitation]
