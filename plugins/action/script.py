"""Action system ``script``: perform a given sequence of movements, then random ones.

How a demonstrator is driven in a scenario ("Morris jumps then covers his face",
Buchsbaum & Blumberg 2005, §5.1; "Moritz performs arbitrary movements",
Kopp & Graeser 2006, §4). It chooses only; it neither interprets nor responds.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from toolkit import ActionSystem, ConfigError, MovementRequest, Parameter, hookimpl


MAX_RANDOM = 100_000
"""The most movements a script draws at random (they are drawn when it is attached)."""


class Script(ActionSystem):
    """Performs the listed movements in order, then `random` movements drawn with `seed`."""

    name = "script"
    parameters = (
        Parameter("movements", list, [], "Movements to perform first, in order.", items=str),
        Parameter("random", int, 0, "How many movements to draw at random from the repertoire afterwards.", minimum=0,
                  maximum=MAX_RANDOM),
        Parameter("exclude", list, [], "Movements never drawn at random.", items=str),
        Parameter("no_repeat", bool, True, "Never draw the same movement twice in a row."),
        Parameter("pause", float, 0.5, "Seconds of standing in the hub between movements.", minimum=0.0,
                  maximum=3600.0),
        Parameter("start", float, 0.5, "Seconds before the first movement.", minimum=0.0, maximum=3600.0),
        Parameter("speed", float, 1.0, "Playback speed of every movement (2 is twice as fast).", minimum=0.01,
                  maximum=100.0),
        Parameter("seed", int, 0, "Seed of the random draws.", minimum=0, maximum=2**63 - 1),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        known = owner.motor.movements()
        for key in ("movements", "exclude"):
            for i, name in enumerate(self.params[key]):
                if name not in known:
                    raise ConfigError(f"unknown movement {name!r}", key=(key, i), expected="a movement of this character", available=known)
        pool = [m for m in known if m not in self.params["exclude"]]
        if self.params["random"] and not pool:
            raise ConfigError("nothing left to draw from", key=("exclude",), expected="at least one movement not excluded", available=known)
        rng = np.random.default_rng(self.params["seed"])
        plan = list(self.params["movements"])
        for _ in range(self.params["random"]):
            choices = [m for m in pool if not (self.params["no_repeat"] and plan and plan[-1] == m and len(pool) > 1)]
            plan.append(str(rng.choice(choices)))
        self.plan = plan
        self._next = 0
        self._idle_since: int | None = None

    def choose(self, actor, world) -> MovementRequest | None:
        if self._next >= len(self.plan):
            return None
        if self._idle_since is None:
            self._idle_since = world.frame
        wait = self.params["start"] if self._next == 0 else self.params["pause"]
        if (world.frame - self._idle_since) / world.fps < wait:
            return None
        movement = self.plan[self._next]
        self._next += 1
        self._idle_since = None
        return MovementRequest(movement, speed=self.params["speed"], reason=f"script step {self._next} of {len(self.plan)}")

    def describe(self) -> dict[str, Any]:
        return {"plan": list(self.plan)}


@hookimpl
def likeme_register_action_systems():
    return [Script]
