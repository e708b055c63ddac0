"""A character with one hand that waves and raises it: wave and raise held at different heights, and a raise held
where the wave is held (issue 34's low style), for the matchers that compare how a hand moves."""

from tests.plugins.matchers.path_search.stick import STICK

__all__ = ["HANDS", "LOW_RAISE"]

HANDS = STICK[: STICK.index("[motor.poses.up]")].replace("Stick", "Hands") + """
[motor.poses]
out = { base = "stand", hand = [0.45, 1.4, 0.2] }
in = { base = "stand", hand = [0.15, 1.4, 0.2] }
held = { base = "stand", hand = [0.3, 1.4, 0.2] }
up = { base = "stand", hand = [0.3, 1.8, 0.1] }

[motor.movements.wave]
keys = [{ pose = "stand", at = 0.0 }, { pose = "held", at = 0.5 }, { pose = "out", at = 0.7 },
        { pose = "in", at = 0.95 }, { pose = "out", at = 1.2 }, { pose = "in", at = 1.45 },
        { pose = "held", at = 1.6 }, { pose = "stand", at = 2.1 }]

[motor.movements.raise]
keys = [{ pose = "stand", at = 0.0 }, { pose = "up", at = 0.6 }, { pose = "up", at = 1.5 },
        { pose = "stand", at = 2.1 }]
"""

LOW_RAISE = """
[motor.movements.low_raise]
keys = [{ pose = "stand", at = 0.0 }, { pose = "held", at = 0.5 }, { pose = "held", at = 1.6 },
        { pose = "stand", at = 2.1 }]
"""
