"""Hand-built streams of a person gesturing (no recording): a standing body of 15 parts (metres, +y up, facing +z),
stances, arm gestures and a bow as key poses joined by minimum-jerk moves, and a tracker's jitter.

The streams the velocity-direction tests watch (``tests/test_velocity_direction_streams.py``): each is a list of
pieces (rests, moves, holds) whose true movements are known by construction.
"""

from __future__ import annotations

import numpy as np

from toolkit import Motion

FPS = 30.0
PARTS = ("root", "chest", "head", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist",
         "right_wrist", "left_hand", "right_hand", "left_knee", "right_knee", "left_foot", "right_foot")
_I = {p: i for i, p in enumerate(PARTS)}


def stance(hands: str = "down", lean: float = 0.0, wide: float = 0.0) -> np.ndarray:
    """A standing pose (15, 3): ``hands`` ``"down"`` (hanging), ``"clasped"`` (in front of the belly) or ``"hips"``
    (on the hips, elbows out); the chest leaning forward by ``lean`` radians; the feet ``wide`` metres further
    apart."""
    p = np.zeros((len(PARTS), 3))
    p[_I["chest"]] = [0.0, 0.45, 0.0]
    p[_I["head"]] = [0.0, 0.72, 0.0]
    for side, x in (("left", 0.19), ("right", -0.19)):
        p[_I[f"{side}_shoulder"]] = [x, 0.42, 0.0]
        hand = {"down": [1.05 * x, -0.18, 0.02], "clasped": [0.04 * np.sign(x), 0.02, 0.22],
                "hips": [1.0 * x, 0.02, -0.02]}[hands]
        arm(p, side, np.array(hand, dtype=float))
        p[_I[f"{side}_knee"]] = [0.1 * np.sign(x) + wide * np.sign(x) / 2, -0.45, 0.02]
        p[_I[f"{side}_foot"]] = [0.1 * np.sign(x) + wide * np.sign(x), -0.9, 0.0]
    return bow(p, lean)


def arm(p: np.ndarray, side: str, hand: np.ndarray) -> np.ndarray:
    """``p`` with the ``side`` arm reaching for ``hand`` (root-relative, metres): the wrist 8 cm short of the hand,
    the elbow half-way and 10 cm out and down."""
    shoulder = p[_I[f"{side}_shoulder"]]
    out = np.array([np.sign(shoulder[0]) * 0.1, -0.1, 0.0])
    p[_I[f"{side}_hand"]] = hand
    p[_I[f"{side}_wrist"]] = hand + 0.08 * (shoulder - hand) / max(np.linalg.norm(shoulder - hand), 1e-9)
    p[_I[f"{side}_elbow"]] = 0.5 * (shoulder + hand) + out
    return p


def bow(p: np.ndarray, angle: float) -> np.ndarray:
    """``p`` with everything above the root turned forward about the x axis by ``angle`` radians."""
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    upper = [i for i, name in enumerate(PARTS) if not name.endswith(("knee", "foot")) and name != "root"]
    p = p.copy()
    p[upper] = p[upper] @ turn.T
    return p


def reach(p: np.ndarray, side: str, hand) -> np.ndarray:
    """A copy of pose ``p`` with one arm reaching for ``hand``."""
    return arm(p.copy(), side, np.asarray(hand, dtype=float))


def move(a: np.ndarray, b: np.ndarray, seconds: float) -> np.ndarray:
    """Poses (n, 15, 3) from ``a`` to ``b`` (``b`` included, ``a`` not) with a minimum-jerk profile."""
    n = max(1, int(round(seconds * FPS)))
    u = np.arange(1, n + 1) / n
    share = u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    return a[None] + share[:, None, None] * (b - a)[None]


def hold(p: np.ndarray, seconds: float) -> np.ndarray:
    """``p`` held ``seconds``."""
    return np.repeat(p[None], max(1, int(round(seconds * FPS))), axis=0)


def wave(p: np.ndarray, seconds: float = 1.6, hold_s: float = 0.0) -> list[np.ndarray]:
    """A wave with the right hand from pose ``p`` back to it: up beside the head, (held ``hold_s``), three swings,
    down."""
    up = reach(p, "right", [-0.3, 0.75, 0.1])
    swings = [reach(p, "right", [-0.45 if k % 2 else -0.15, 0.75, 0.1]) for k in range(3)] + [up]
    pieces = [move(p, up, seconds * 0.3)] + ([hold(up, hold_s)] if hold_s else [])
    prev = up
    for q in swings:
        pieces.append(move(prev, q, seconds * 0.1))
        prev = q
    return pieces + [move(prev, p, seconds * 0.3)]


def point(p: np.ndarray, seconds: float = 1.2, hold_s: float = 0.0) -> list[np.ndarray]:
    """The right arm points forward from pose ``p``, holds ``hold_s`` seconds, and comes back."""
    out = reach(p, "right", [-0.25, 0.45, 0.65])
    return [move(p, out, seconds / 2)] + ([hold(out, hold_s)] if hold_s else []) + [move(out, p, seconds / 2)]


def bowing(p: np.ndarray, seconds: float = 1.4, hold_s: float = 0.0) -> list[np.ndarray]:
    """A bow from pose ``p``: forward by 0.6 rad, held ``hold_s`` seconds, and up again."""
    down = bow(p, 0.6)
    return [move(p, down, seconds / 2)] + ([hold(down, hold_s)] if hold_s else []) + [move(down, p, seconds / 2)]


def stream(pieces: list[tuple[str, list[np.ndarray]]], jitter: float = 0.0, seed: int = 0,
           size: float = 1.0) -> tuple[Motion, list[tuple[int, int]]]:
    """A stream of ``(kind, poses)`` pieces, ``kind`` ``"movement"`` (a true movement) or anything else (rest,
    shift); ``jitter`` metres of tracker noise on every coordinate; the body ``size`` times as large. The motion and
    the true movements (start, end exclusive)."""
    frames, truth, at = [], [], 0
    for kind, poses in pieces:
        n = sum(len(x) for x in poses)
        if kind == "movement":
            truth.append((at, at + n))
        frames += poses
        at += n
    positions = np.concatenate(frames) * size
    if jitter:
        positions = positions + np.random.default_rng(seed).normal(0.0, jitter, positions.shape)
    return Motion(positions, FPS, PARTS), truth
