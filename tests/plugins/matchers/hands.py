"""A character with one hand that waves and raises it: wave and raise held at different heights, and a raise held
where the wave is held (issue 34's low style), for the matchers that compare how a hand moves."""

from tests.plugins.matchers.path_search.stick import STICK

__all__ = ["HANDS", "LOW_RAISE", "holding", "waving"]


def waving(name: str, swings: int) -> str:
    """The movement ``name``: the hand up to where it is held in half a second, ``swings`` swings out and in of a
    quarter of a second each, and down again."""
    times = [0.7 + 0.25 * k for k in range(swings)]
    keys = [("stand", 0.0), ("held", 0.5), *((("out", "in")[k % 2], t) for k, t in enumerate(times)),
            ("held", times[-1] + 0.15), ("stand", times[-1] + 0.65)]
    return f"\n[motor.movements.{name}]\nkeys = [" + ", ".join(
        f'{{ pose = "{pose}", at = {at:.2f} }}' for pose, at in keys) + "]\n"


def holding(name: str, pose: str, reach: float = 0.6, leave: float = 1.5, end: float = 2.1) -> str:
    """The movement ``name``: the hand to ``pose`` by ``reach`` seconds, held there until ``leave``, back by ``end``."""
    return (f'\n[motor.movements.{name}]\nkeys = [{{ pose = "stand", at = 0.0 }}, {{ pose = "{pose}", at = {reach} }}, '
            f'{{ pose = "{pose}", at = {leave} }}, {{ pose = "stand", at = {end} }}]\n')


HANDS = STICK[: STICK.index("[motor.poses.up]")].replace("Stick", "Hands") + """
[motor.poses]
out = { base = "stand", hand = [0.45, 1.4, 0.2] }
in = { base = "stand", hand = [0.15, 1.4, 0.2] }
held = { base = "stand", hand = [0.3, 1.4, 0.2] }
up = { base = "stand", hand = [0.3, 1.8, 0.1] }
""" + waving("wave", 4) + holding("raise", "up")

LOW_RAISE = holding("low_raise", "held", reach=0.5, leave=1.6)
