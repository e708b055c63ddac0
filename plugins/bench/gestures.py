"""Hand gestures of several performers in several styles, as a depth camera's skeleton tracker records them.

A benchmark folder (``likeme bench make-gestures DIR``) for what the public clips do not hold: waves and raises of
the left, the right and both hands, performed by people of different sizes and habits in seven styles, with a
Kinect v1's 20 joints in its camera's frame (metres, a time column, jitter, joints lost). It stands in for the data
issue 34 describes (``docs/benchmarks.md``, "Hand gestures"): a wave and a raise of one hand differ by the
reversals of the hand, not by where the hand is, because the styles move where it is held:

- ``normal``: a raise lifts the hand above the head and holds it; a wave holds it beside the head and swings it;
- ``low``: both held lower, at the chest and the face: a low raise goes where a normal wave is held;
- ``high``: both held higher: a high wave is held where a normal raise ends;
- ``fast``, ``slow``: the same at about 0.55x and 1.9x the duration (3.5x apart, up to 4x with the performers'
  own tempi); ``big``: wider swings, the body rocking with them; ``tired``: slow, low and stooped, fewer swings.

Every performer has a height (1.55 to 1.95 m), arm proportions, a stoop, a wave's frequency (1.4 to 2.6 Hz) and
number of reversals (4 to 9, a raise 0 or 1), a way to stand, and a place before the camera. Takes of one style
recorded one after another differ by a few percent. Nothing here is fitted to a matcher: the kinematics are a
standing body, two-bone arms reaching for hand targets on minimum-jerk paths (Flash & Hogan 1985), and a swing
about the held place.

Layout (``takes:N`` and ``open`` protocols of ``likeme bench recognition``): ``repertoire/MOVEMENT/`` holds the first
performer's ``normal`` takes, ``demos/MOVEMENT/`` every style of every performer (the first performer's ``normal``
excepted), ``profile.toml`` the body profile.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["JOINTS", "MOVEMENTS", "STYLES", "Performer", "Style", "gesture", "make_gestures"]

FPS = 30.0
JOINTS = ("HipCenter", "Spine", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft",
          "ShoulderRight", "ElbowRight", "WristRight", "HandRight", "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft",
          "HipRight", "KneeRight", "AnkleRight", "FootRight")
"""The Kinect v1 skeleton's joints, in the order of its SDK."""
_J = {name: i for i, name in enumerate(JOINTS)}
MOVEMENTS = ("wave_left", "wave_right", "wave_both", "raise_left", "raise_right", "raise_both")
_UPPER = ("Spine", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft", "ShoulderRight",
          "ElbowRight", "WristRight", "HandRight")


@dataclass(frozen=True)
class Style:
    """How a style changes a gesture: the held place (``"normal"``, ``"low"``, ``"high"``), the tempo (durations
    times ``tempo``), the swing's size, the number of reversals added, the stoop added (radians) and how much the body
    rocks with a swing."""

    place: str = "normal"
    tempo: float = 1.0
    swing: float = 1.0
    reversals: int = 0
    stoop: float = 0.0
    rock: float = 0.0


STYLES = {
    "normal": Style(),
    "low": Style(place="low", swing=0.8),
    "high": Style(place="high"),
    "fast": Style(tempo=0.55),
    "slow": Style(tempo=1.9),
    "big": Style(swing=1.5, reversals=2, rock=0.025),
    "tired": Style(place="low", tempo=1.6, swing=0.7, reversals=-2, stoop=0.18),
}
"""The seven styles, by name."""

# Where a wrist is held, relative to its shoulder in arm's lengths (x across to the arm's own side, y up, z forward).
_HELD = {
    ("wave", "normal"): (0.35, 0.46, 0.25), ("raise", "normal"): (0.12, 0.91, 0.14),
    ("wave", "low"): (0.25, -0.21, 0.53), ("raise", "low"): (0.21, 0.42, 0.39),
    ("wave", "high"): (0.14, 0.84, 0.18), ("raise", "high"): (0.07, 0.96, 0.04),
}
_REST = (0.09, -0.91, 0.10)


@dataclass(frozen=True)
class Performer:
    """One person: ``size`` (metres from the floor to the top of the head), arm proportions, a stoop (radians), a
    wave's frequency (Hz) and reversals, how far from the body the hands hang at rest, and where the camera sees them
    (metres to the side, metres from the camera, the turn away from it in radians)."""

    size: float
    upper_arm: float
    forearm: float
    stoop: float
    frequency: float
    reversals: int
    rest_out: float
    x: float
    distance: float
    yaw: float

    @classmethod
    def draw(cls, rng: np.random.Generator) -> "Performer":
        """A performer drawn from the ranges of the module's docstring."""
        return cls(size=rng.uniform(1.55, 1.95), upper_arm=rng.uniform(0.17, 0.19), forearm=rng.uniform(0.145, 0.165),
                   stoop=rng.uniform(0.0, 0.12), frequency=rng.uniform(1.4, 2.6), reversals=int(rng.integers(4, 10)),
                   rest_out=rng.uniform(0.0, 0.12), x=rng.uniform(-0.4, 0.4), distance=rng.uniform(2.3, 3.2),
                   yaw=rng.uniform(-0.25, 0.25))


def _standing(p: Performer, stoop: float) -> np.ndarray:
    """The performer's standing pose in the body's frame (20, 3): metres, the floor at y = 0, facing +z, +x the
    body's left."""
    s = p.size
    q = np.zeros((len(JOINTS), 3))
    hip = 0.53 * s
    q[_J["HipCenter"]] = [0, hip, 0]
    q[_J["Spine"]] = [0, hip + 0.1 * s, 0]
    q[_J["ShoulderCenter"]] = [0, hip + 0.29 * s, 0]
    q[_J["Head"]] = [0, hip + 0.41 * s, 0.01 * s]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        q[_J[f"Shoulder{side}"]] = [sign * 0.105 * s, hip + 0.27 * s, 0]
        q[_J[f"Hip{side}"]] = [sign * 0.055 * s, hip - 0.03 * s, 0]
        q[_J[f"Knee{side}"]] = [sign * 0.06 * s, 0.28 * s, 0.01 * s]
        q[_J[f"Ankle{side}"]] = [sign * 0.065 * s, 0.04 * s, -0.01 * s]
        q[_J[f"Foot{side}"]] = [sign * 0.07 * s, 0.01 * s, 0.07 * s]
    upper = [_J[n] for n in _UPPER]
    return _lean(q, upper, q[_J["HipCenter"]], stoop)


def _lean(q: np.ndarray, rows: list[int], about: np.ndarray, angle) -> np.ndarray:
    """``q`` (…, 20, 3) with ``rows`` turned forward about the x axis through ``about`` by ``angle`` radians (a scalar
    or one per frame)."""
    angle = np.asarray(angle, dtype=float)[..., None]
    c, s = np.cos(angle), np.sin(angle)
    out = q.copy()
    rel = q[..., rows, :] - about
    out[..., rows, 1] = about[..., 1, None] + c * rel[..., 1] - s * rel[..., 2]
    out[..., rows, 2] = about[..., 2, None] + s * rel[..., 1] + c * rel[..., 2]
    return out


def _min_jerk(u: np.ndarray) -> np.ndarray:
    """The minimum-jerk profile from 0 to 1 over u in [0, 1] (Flash & Hogan 1985)."""
    u = np.clip(u, 0.0, 1.0)
    return u ** 3 * (10.0 - 15.0 * u + 6.0 * u * u)


def _reach(shoulder: np.ndarray, wrist: np.ndarray, upper: float, fore: float, sign: float) -> tuple:
    """Two-bone inverse kinematics (per frame): the elbow and the wrist reached for ``wrist`` from ``shoulder``, the
    elbow bent down, out to the arm's side (``sign``) and back."""
    d = wrist - shoulder
    dist = np.linalg.norm(d, axis=-1, keepdims=True)
    u = d / np.maximum(dist, 1e-9)
    dist = np.clip(dist, abs(upper - fore) + 1e-3, upper + fore - 1e-3)
    along = (upper ** 2 - fore ** 2 + dist ** 2) / (2.0 * dist)
    height = np.sqrt(np.maximum(upper ** 2 - along ** 2, 0.0))
    pole = np.array([0.6 * sign, -1.0, -0.4])
    pole = pole - (u @ pole)[..., None] * u
    pole /= np.maximum(np.linalg.norm(pole, axis=-1, keepdims=True), 1e-9)
    elbow = shoulder + along * u + height * pole
    return elbow, shoulder + dist * u


def _arm(shoulder: np.ndarray, wrist: np.ndarray, p: Performer, sign: float) -> tuple:
    """The elbow, wrist and hand (each (n, 3)) of an arm of ``p`` reaching from ``shoulder`` for ``wrist``: the hand
    on from the wrist along the forearm."""
    s = p.size
    elbow, wrist = _reach(shoulder, wrist, p.upper_arm * s, p.forearm * s, sign)
    forearm = wrist - elbow
    return elbow, wrist, wrist + 0.045 * s * forearm / np.maximum(np.linalg.norm(forearm, axis=-1, keepdims=True),
                                                                   1e-9)


def _rest(p: Performer, sign: float) -> np.ndarray:
    """Where ``p``'s wrist hangs at rest relative to its shoulder (m), on the arm's own side (``sign``)."""
    return np.array([sign * (_REST[0] + p.rest_out), _REST[1], _REST[2]]) * ((p.upper_arm + p.forearm) * p.size)


def gesture(movement: str, style: Style, p: Performer, rng: np.random.Generator, *, vary: float = 0.04) -> np.ndarray:
    """One take (frames, 20, 3), in the body's frame: ``movement`` of :data:`MOVEMENTS` in ``style`` by ``p``; every
    duration, place and swing varied by about ``vary`` (a take recorded after another differs by a few percent)."""
    kind, hands = movement.split("_")
    jitter = lambda x: x * (1.0 + vary * rng.standard_normal())  # noqa: E731
    tempo = style.tempo
    reversals = 1 if kind == "raise" and rng.random() < 0.5 else 0
    if kind == "wave":
        reversals = max(2, p.reversals + style.reversals + int(rng.integers(-1, 2)))
    frequency = jitter(p.frequency) / tempo
    hold = reversals / (2.0 * frequency) if kind == "wave" else jitter(0.9) * tempo
    lift, lower = jitter(0.6) * tempo, jitter(0.65) * tempo
    before, after = jitter(0.6), jitter(0.6)
    n = int(round((before + lift + hold + lower + after) * FPS))
    t = np.arange(n) / FPS
    stoop = p.stoop + style.stoop
    q = np.repeat(_standing(p, stoop)[None], n, axis=0)
    s = p.size
    reach = (p.upper_arm + p.forearm) * s
    # Standing is never still: the body sways a centimetre, slowly.
    sway = 0.008 * s * np.sin(2 * np.pi * jitter(0.25) * t + rng.uniform(0, 2 * np.pi))
    q[:, :, 0] += sway[:, None]
    up = _min_jerk((t - before) / lift)
    down = _min_jerk((t - before - lift - hold) / lower)
    level = up - down
    held_place = _HELD[(kind, style.place)]
    start, end = before + lift, before + lift + hold
    during = (t >= start) & (t < end)
    phase = np.where(during, (t - start) / max(hold, 1e-9), 0.0)
    arms = {"left": ("Left", 1.0), "right": ("Right", -1.0)}
    sides = list(arms) if hands == "both" else [hands]
    rock = np.zeros(n)
    for k, side in enumerate(sides):
        name, sign = arms[side]
        lag = 0.05 * k * rng.random()
        shoulder = q[:, _J[f"Shoulder{name}"]].copy()
        # the shoulder rises a little as the hand goes above it
        shoulder[:, 1] += 0.015 * s * level * (held_place[1] > 0.3)
        q[:, _J[f"Shoulder{name}"]] = shoulder
        rest = _rest(p, sign)
        held = np.array([sign * held_place[0], held_place[1], held_place[2]]) * reach * jitter(1.0)
        path = rest + level[:, None] * (held - rest)
        path[:, 2] += 0.2 * reach * np.sin(np.pi * np.clip(level, 0, 1))  # the hand passes in front of the body
        if kind == "wave":
            amp = 0.16 * reach * style.swing * jitter(1.0)
            x = np.clip(phase - lag, 0.0, 1.0)
            swing = np.sin(np.pi * reversals * x) * _min_jerk(4.0 * x) * _min_jerk(4.0 * (1.0 - x)) * during
            path[:, 0] += sign * amp * swing
            path[:, 1] -= 0.2 * amp * np.abs(swing)
            rock += style.rock * s * swing / len(sides)
        else:
            path[:, 1] += 0.02 * s * np.sin(np.pi * reversals * phase) * during
        path += 0.003 * s * np.sin(2 * np.pi * jitter(0.7) * t + rng.uniform(0, 2 * np.pi))[:, None]
        q[:, [_J[f"Elbow{name}"], _J[f"Wrist{name}"], _J[f"Hand{name}"]]] = np.stack(
            _arm(shoulder, shoulder + path, p, sign), axis=1)
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        if side.lower() not in sides:  # the other arm hangs at rest
            shoulder = q[:, _J[f"Shoulder{side}"]]
            q[:, [_J[f"Elbow{side}"], _J[f"Wrist{side}"], _J[f"Hand{side}"]]] = np.stack(
                _arm(shoulder, shoulder + _rest(p, sign), p, sign), axis=1)
    upper = [_J[n] for n in _UPPER]
    q[:, upper, 0] += rock[:, None] * (q[:, upper, 1] - q[:, _J["HipCenter"], 1][:, None]) / (0.4 * s)
    return q


def _camera(q: np.ndarray, p: Performer, rng: np.random.Generator, *, height: float, tilt: float,
            jitter: float, lost: float) -> np.ndarray:
    """Body-frame positions as the depth camera's tracker gives them: the body turned by ``p.yaw`` and placed
    ``p.distance`` metres before a camera ``height`` metres up and tilted down by ``tilt`` radians; x to the camera's
    left, y up, z away from it; Gaussian jitter (``jitter`` metres, twice that at the wrists and hands) and each
    joint lost (NaN) in a ``lost`` share of the frames, in runs of one to four frames."""
    c, s = np.cos(p.yaw), np.sin(p.yaw)
    world = q.copy()
    world[..., 0], world[..., 2] = c * q[..., 0] + s * q[..., 2] + p.x, -s * q[..., 0] + c * q[..., 2]
    cam = np.stack([-world[..., 0], world[..., 1] - height, p.distance - world[..., 2]], axis=-1)
    ct, st = np.cos(tilt), np.sin(tilt)
    cam = np.stack([cam[..., 0], ct * cam[..., 1] + st * cam[..., 2], -st * cam[..., 1] + ct * cam[..., 2]], axis=-1)
    scale = np.full(len(JOINTS), jitter)
    scale[[_J[n] for n in ("WristLeft", "HandLeft", "WristRight", "HandRight")]] *= 2.0
    cam = cam + rng.normal(0.0, 1.0, cam.shape) * scale[None, :, None]
    starts = rng.random(cam.shape[:2]) < lost / 2.5
    for length in range(1, 5):
        cam[np.roll(starts, length - 1, axis=0) & (np.arange(len(cam))[:, None] >= length - 1)] = np.nan
    return cam


PROFILE = """\
# Body profile of the Kinect v1 joint positions likeme bench make-gestures writes (CSV, a time column, metres,
# the camera's frame: +y up, tilted down by a few degrees, the floor below the camera).
bones = [["root", "chest"], ["chest", "head"], ["chest", "left_shoulder"], ["left_shoulder", "left_elbow"],
         ["left_elbow", "left_wrist"], ["left_wrist", "left_hand"], ["chest", "right_shoulder"],
         ["right_shoulder", "right_elbow"], ["right_elbow", "right_wrist"], ["right_wrist", "right_hand"],
         ["root", "left_hip"], ["left_hip", "left_knee"], ["left_knee", "left_foot"], ["left_foot", "left_toes"],
         ["root", "right_hip"], ["right_hip", "right_knee"], ["right_knee", "right_foot"], ["right_foot", "right_toes"]]

[profile]
name = "kinect-v1-gestures"
description = "hand gestures of several performers (likeme bench make-gestures)"
units = "metre"
up = "+y"
floor = {floor}

[parts]
root = "HipCenter"
chest = "ShoulderCenter"
head = "Head"
left_shoulder = "ShoulderLeft"
left_elbow = "ElbowLeft"
left_wrist = "WristLeft"
left_hand = "HandLeft"
right_shoulder = "ShoulderRight"
right_elbow = "ElbowRight"
right_wrist = "WristRight"
right_hand = "HandRight"
left_hip = "HipLeft"
left_knee = "KneeLeft"
left_foot = "AnkleLeft"
left_toes = "FootLeft"
right_hip = "HipRight"
right_knee = "KneeRight"
right_foot = "AnkleRight"
right_toes = "FootRight"

[facing]
left = ["left_hip", "left_shoulder"]
right = ["right_hip", "right_shoulder"]
"""


def make_gestures(dest: Path, *, seed: int = 0, performers: int = 4, takes: int = 4, jitter: float = 0.01,
                  lost: float = 0.02, jobs: int = 1, scheduler: str | None = None) -> Path:
    """Write the gestures folder (the module's docstring) to ``dest``: ``takes`` takes of the first performer's
    ``normal`` style in ``repertoire/MOVEMENT/``, one take of every other (performer, style) in ``demos/MOVEMENT/``,
    and ``profile.toml``. File names ``gestures_MOVEMENT_STYLE_pK_NNN.csv`` (the movement with a hyphen).

    Every take is performed and every noise drawn here, in order; the CSV files are then written as items of
    :func:`plugins.bench.jobs.run_items` (``jobs`` local processes or the Dask ``scheduler``): the same ``seed``
    writes the same files whatever wrote them."""
    from plugins.bench.jobs import run_items

    dest = Path(dest)
    rng = np.random.default_rng(seed)
    people = [Performer.draw(rng) for _ in range(performers)]
    height, tilt = 0.8, np.radians(5.0)
    items = []
    for movement in MOVEMENTS:
        for k, p in enumerate(people):
            for style_name, style in STYLES.items():
                own = k == 0 and style_name == "normal"
                folder = dest / ("repertoire" if own else "demos") / movement
                folder.mkdir(parents=True, exist_ok=True)
                for take in range(1, (takes if own else 1) + 1):
                    q = gesture(movement, style, p, rng)
                    cam = _camera(q, p, rng, height=height, tilt=tilt, jitter=jitter, lost=lost)
                    name = f"gestures_{movement.replace('_', '-')}_{style_name}_p{k + 1}_{take:03d}.csv"
                    items.append({"path": str(folder / name), "positions": cam})
    run_items(_write_take, items, jobs=jobs, scheduler=scheduler)
    # the floor below the camera, where a performer stands at the middle distance (the tilt raises it there)
    floor = -height * np.cos(tilt) + 2.75 * np.sin(tilt)
    (dest / "profile.toml").write_text(PROFILE.replace("{floor}", f"{floor:.2f}"), encoding="utf-8")
    return dest


def _write_take(item: dict) -> str:
    """One CSV file of :func:`make_gestures`: the joints' positions with a time column."""
    from plugins.bench.data import write_positions

    return str(write_positions(Path(item["path"]), list(JOINTS), item["positions"], fps=FPS))


def cmd_make_gestures(args, pm) -> int:
    """``likeme bench make-gestures DIR``: written to a staging folder inside DIR and moved into it when complete
    (:func:`toolkit.files.writing_folder`)."""
    from toolkit.files import writing_folder

    with writing_folder(args.dest, "benchmark data") as stage:
        make_gestures(stage, seed=args.seed, performers=args.performers, takes=args.takes, jitter=args.jitter,
                      lost=args.lost, jobs=args.jobs, scheduler=args.scheduler)
    print(Path(args.dest))
    return 0
