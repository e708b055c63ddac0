"""The perception's quick paths (plugins.lib.root_frame, issue 22) give the same bits as the formulas they replace.

``Before`` below is root_frame as it was before this work (the transform through ``toolkit.motion.world_to_local``'s
einsum, finiteness as an ``all`` over the coordinates, the middle of a row by ``np.partition``, the first rows of a
stream by ``np.nanmedian``; the facing is shared, its cross product pinned to ``np.cross`` on its own): every quick
path is compared with it byte for byte (signed zeros included), over
bodies with and without finger angles and with a forward marker seen from its own behind part, hidden parts,
non-finite coordinates, headings about ±π and ties.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib import root_frame
from plugins.lib.root_frame import (_UP, HeadingFilter, _circular_median, _cross_up, _finite_points, _to_local,
                                    _zero_hidden, RecordingFacing, facing_heading, marker_behind, root_relative,
                                    smooth_heading, to_root_relative)
from plugins.perception.motion_capture import MotionCapture
from tests.conftest import CHARACTERS, ROOT
from toolkit import create_plugin_manager, load_character
from toolkit.motion import local_to_world, world_to_local
from toolkit.recordings.profile import load_profile


class Before:
    """root_frame's transform and running median before the quick paths, written out as they were."""

    @staticmethod
    def to_root_relative(world, visible, body, heading=None):
        world = np.asarray(world, dtype=float)
        visible = np.asarray(visible, dtype=bool) & np.isfinite(world).all(axis=-1)
        if heading is None:
            heading = facing_heading(np.where(visible[..., None], world, 0.0), visible, body)
        heading = np.asarray(heading, dtype=float)
        root = world[..., body.root_index, :]
        ok = visible[..., body.root_index] & np.isfinite(heading)
        safe_world = np.where(visible[..., None], world, 0.0)
        safe_root = np.where(ok[..., None], root, 0.0)
        safe_heading = np.where(ok, heading, 0.0)
        if world.ndim == 2:
            pose = world_to_local(safe_world, safe_root, float(safe_heading))
        else:
            flat = safe_world.reshape(-1, *world.shape[-2:])
            pose = world_to_local(flat, safe_root.reshape(-1, 3), safe_heading.reshape(-1)).reshape(world.shape)
        mask = visible & ok[..., None]
        angles = body.angle_mask
        if angles.any():
            pose[..., angles, :] = world[..., angles, :]
            mask = mask & mask[..., body.carriers]
        pose = np.where(mask[..., None], pose, np.nan)
        return pose, mask, np.where(ok[..., None], root, np.nan), heading

    @staticmethod
    def root_relative(world, visible, body, smooth=None, vote=None):
        """``vote`` (window, centred): the forward marker's side put to a vote, as :func:`votes` writes it out; or
        the votes themselves (an array)."""
        world = np.asarray(world, dtype=float)
        seen = np.isfinite(world).all(axis=-1)
        visible = seen if visible is None else seen & np.asarray(visible, dtype=bool)
        safe = np.where(visible[..., None], world, 0.0)
        behind = None
        if isinstance(vote, np.ndarray):
            behind = vote
        elif vote is not None and body.facing.forward is not None:
            behind = votes(marker_behind(safe, visible, body), *vote)
        found = facing_heading(safe, visible, body, None if behind is None else Given(behind))
        return Before.to_root_relative(world, visible, body, found if smooth is None else smooth(found))

    @staticmethod
    def unwrapped_median(angles, ref):
        n, w = angles.shape
        d = angles - ref
        spread = np.abs(d)
        if not len(d) or not (spread <= 64.0).all():
            return np.median(root_frame._unwrapped(angles, ref), axis=1) if len(d) else np.zeros(0)
        if spread.max() < np.pi - root_frame._WRAP:
            quick, near = angles, np.zeros(angles.shape, dtype=bool)
        else:
            turns = np.round(d / (2 * np.pi))
            wrapped = d - 2 * np.pi * turns
            quick = ref + wrapped
            near = np.abs(np.abs(wrapped) - np.pi) < root_frame._WRAP
            if near.any():
                quick[near] = root_frame._unwrapped(angles[near], np.broadcast_to(ref, angles.shape)[near])
        ranks = [(w - 1) // 2, w // 2]
        middle = np.partition(quick, ranks, axis=1)[:, ranks]
        lo, hi = middle[:, :1] - 2 * root_frame._CLOSE, middle[:, 1:] + 2 * root_frame._CLOSE
        below = (quick < lo).sum(axis=1)
        band = (quick >= lo) & (quick <= hi)
        rows, cols = np.nonzero(band)
        exact = quick[rows, cols]
        far = ~near[rows, cols]
        exact[far] = root_frame._unwrapped(angles[rows[far], cols[far]], ref[rows[far], 0])
        exact = exact[np.lexsort((exact, rows))]
        first = np.concatenate([[0], np.cumsum(band.sum(axis=1))[:-1]])
        a, b = exact[first + ranks[0] - below], exact[first + ranks[1] - below]
        return np.where(ranks[0] == ranks[1], a, (a + b) / 2)

    @staticmethod
    def circular_median(windows, rotations=None):
        ok = np.isfinite(windows)
        angles = np.where(ok, windows, 0.0)
        if rotations is None:
            rotations = np.where(ok, np.exp(1j * angles), 0.0)
        ref = np.angle(rotations.sum(axis=1))[:, None]
        out = np.full(len(windows), np.nan)
        full, some = ok.all(axis=1), ok.any(axis=1)
        if full.any():
            out[full] = Before.unwrapped_median(angles[full], ref[full])
        partial = some & ~full
        if partial.any():
            a, r = angles[partial], ref[partial]
            out[partial] = np.nanmedian(np.where(ok[partial], r + np.angle(np.exp(1j * (a - r))), np.nan), axis=1)
        return np.angle(np.exp(1j * out))

    @staticmethod
    def windowed_median(padded, window, rows):
        finite = np.isfinite(padded)
        rotations = np.where(finite, np.exp(1j * np.where(finite, padded, 0.0)), 0.0)
        view = np.lib.stride_tricks.sliding_window_view(padded, window)
        turned = np.lib.stride_tricks.sliding_window_view(rotations, window)
        step = max(1, root_frame._WINDOW_BUDGET // max(1, window))
        return np.concatenate([Before.circular_median(view[rows[i : i + step]], turned[rows[i : i + step]])
                               for i in range(0, len(rows), step)]) if len(rows) else np.zeros(0)

    class HeadingFilter:
        def __init__(self, window):
            self.window, self._recent = max(1, int(window)), []

        def update(self, heading):
            if np.isfinite(heading):
                self._recent.append(float(heading))
                if len(self._recent) > self.window:
                    del self._recent[0]
            if not self._recent:
                return float("nan")
            return float(Before.circular_median(np.asarray(self._recent)[None])[0])

        def update_many(self, headings):
            h = np.asarray(headings, dtype=float)
            finite = np.isfinite(h)
            estimates = np.concatenate([np.asarray(self._recent, dtype=float), h[finite]])
            ends = len(self._recent) + np.cumsum(finite)
            self._recent = estimates[-self.window :].tolist()
            out = np.full(len(h), np.nan)
            have = ends > 0
            if not have.any():
                return out
            padded = np.concatenate([np.full(self.window - 1, np.nan), estimates])
            out[have] = Before.windowed_median(padded, self.window, ends[have] - 1)
            return out

    @staticmethod
    def smooth_heading(heading, window):
        heading = np.asarray(heading, dtype=float)
        n, half = len(heading), max(1, int(window)) // 2
        if n == 0 or window <= 1 or not np.isfinite(heading).any():
            return heading.copy()
        padded = np.pad(heading, half, constant_values=np.nan)
        return Before.windowed_median(padded, 2 * half + 1, np.arange(n))


class Given:
    """A window whose vote is given (the reference's, :func:`votes`)."""

    def __init__(self, shares):
        self.shares = np.asarray(shares, dtype=float)

    def votes(self, flags):
        return self.shares.reshape(np.shape(flags))


def votes(flags, window, centred):
    """The marker's vote written out frame by frame: the sum of the finite flags of the window ending at (stream)
    or centred on (recording) each frame, over the window's length; a stream's window holds its last ``window``
    finite flags."""
    flags = np.asarray(flags, dtype=float).reshape(-1)
    out = np.full(len(flags), np.nan)
    for i in range(len(flags)):
        if centred:
            half = max(1, window) // 2
            near = flags[max(0, i - half) : i + half + 1]
            near = near[np.isfinite(near)]
        else:
            near = flags[: i + 1]
            near = near[np.isfinite(near)][-max(1, window):]
        if len(near):
            out[i] = near.sum() / (2 * (max(1, window) // 2) + 1 if centred else max(1, window))
    return out


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


_PM = create_plugin_manager(autoload=False)
BODIES = {
    "max": load_character(CHARACTERS / "max.toml", _PM).body,  # knees and nose
    "moritz": load_character(CHARACTERS / "moritz.toml", _PM).body,  # finger angles carried by the wrists
    "bandai": load_profile(ROOT / "characters" / "profiles" / "bandai-namco.toml").body,  # toe tip seen from toes
}
REST = {name: np.asarray(load_character(CHARACTERS / f"{name}.toml", _PM).motor.rest_pose())
        for name in ("max", "moritz")}


def _rest(name, body, rng):
    if name in REST:
        return REST[name]
    return rng.normal(0.0, 0.4, (body.n_parts, 3))  # a profile body has no rest pose here: any layout will do


def frames(name, rng, n, *, turn, hidden, bad, zeros):
    """Frames (n, P, 3) of a body walking and turning (``turn``: radians per frame, about ±π too), parts hidden at
    random, non-finite coordinates, exact zeros (the root at the origin, on the axes)."""
    body = BODIES[name]
    rest = _rest(name, body, rng)
    local = rest[None] + rng.normal(0.0, 0.03, (n, body.n_parts, 3))
    headings = np.pi + np.cumsum(rng.normal(0.0, turn, n))
    positions = np.cumsum(rng.normal(0.0, 0.02, (n, 3)), axis=0)
    world = local_to_world(local, positions, headings)
    if zeros:
        world[rng.random(world.shape) < 0.05] = 0.0
        world[rng.random(world.shape) < 0.03] = -0.0
        world[rng.random(n) < 0.2, body.root_index] = 0.0
    visible = rng.random((n, body.n_parts)) >= hidden
    if bad:
        world[rng.random(world.shape) < bad] = rng.choice([np.nan, np.inf, -np.inf])
    return world, visible


def _angles(rng, shape):
    kind = rng.integers(6)
    if kind == 0:
        return np.angle(np.exp(1j * np.cumsum(rng.normal(0, 0.1, shape), axis=-1)))
    if kind == 1:
        return np.where(rng.random(shape) < 0.2, np.pi * np.sign(rng.normal(size=shape)), rng.normal(0, 0.3, shape))
    if kind == 2:  # ties, and exact zeros of both signs
        return np.round(rng.normal(0, 1, shape), 1) * rng.choice([1.0, -1.0], shape)
    if kind == 3:
        return np.angle(np.exp(1j * (np.pi + rng.normal(0, 0.01, shape))))
    if kind == 4:
        return rng.normal(0, 100, shape)
    return rng.uniform(-np.pi, np.pi, shape)


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 40), parts=st.integers(1, 25), zeros=st.floats(0.0, 0.6),
       special=st.floats(0.0, 1.0))
def test_the_transform_written_out_is_world_to_local_bit_for_bit(seed, n, parts, zeros, special):
    rng = np.random.default_rng(seed)
    points = rng.normal(0, 1, (n, parts, 3)) * rng.choice([1e-300, 1e-3, 1.0, 1e3, 1e300], (n, parts, 3))
    points[rng.random(points.shape) < zeros] = 0.0
    points[rng.random(points.shape) < zeros / 2] = -0.0
    origin = np.where(rng.random((n, 3)) < zeros, rng.choice([0.0, -0.0], (n, 3)), rng.normal(0, 2, (n, 3)))
    heading = rng.uniform(-4, 4, n)
    pick = rng.random(n) < special
    heading[pick] = rng.choice([0.0, -0.0, np.pi, -np.pi, np.pi / 2, -np.pi / 2, 1e-300], pick.sum())
    assert same_bits(_to_local(points, origin, heading), world_to_local(points, origin, heading))


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 10), bad=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_the_transform_of_non_finite_values_is_world_to_local(seed, n, bad):
    rng = np.random.default_rng(seed)
    points, origin, heading = rng.normal(size=(n, 4, 3)), rng.normal(size=(n, 3)), rng.normal(size=n)
    [points, origin, heading][rng.integers(3)].reshape(-1)[rng.integers(n)] = bad
    with np.errstate(invalid="ignore"):  # the cosine of an infinite heading is NaN, as meant here
        assert same_bits(_to_local(points, origin, heading), world_to_local(points, origin, heading))


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**31), shape=st.lists(st.integers(1, 30), min_size=0, max_size=2),
       zeros=st.floats(0.0, 0.5), bad=st.floats(0.0, 0.2))
def test_the_cross_product_with_up_is_np_cross_bit_for_bit(seed, shape, zeros, bad):
    """facing_heading's only change: its cross product written out (``Before`` shares the rest of it)."""
    rng = np.random.default_rng(seed)
    across = rng.normal(size=(*shape, 3)) * rng.choice([1e-300, 1.0, 1e300], (*shape, 3))
    across[rng.random(across.shape) < zeros] = rng.choice([0.0, -0.0])
    across[rng.random(across.shape) < bad] = rng.choice([np.nan, np.inf, -np.inf])
    with np.errstate(all="ignore"):
        assert same_bits(_cross_up(across), np.cross(across, _UP))


def test_a_difference_that_overflows_is_transformed_as_world_to_local():
    points = np.full((2, 3, 3), 1.5e308)
    origin = np.full((2, 3), -1.5e308)  # finite both, their difference is not
    heading = np.array([0.3, -2.0])
    with np.errstate(all="ignore"):
        assert same_bits(_to_local(points, origin, heading), world_to_local(points, origin, heading))


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**31), shape=st.lists(st.integers(0, 6), min_size=0, max_size=3),
       last=st.sampled_from([3, 3, 3, 1, 2]), bad=st.floats(0.0, 0.5))
def test_finite_points_and_the_zeroed_world_are_the_formulas(seed, shape, last, bad):
    rng = np.random.default_rng(seed)
    world = rng.normal(size=(*shape, last))
    world[rng.random(world.shape) < bad] = rng.choice([np.nan, np.inf, -np.inf])
    assert same_bits(_finite_points(world), np.isfinite(world).all(axis=-1))
    visible = rng.random(world.shape[:-1]) < 0.5 + bad
    assert same_bits(_zero_hidden(world, visible), np.where(visible[..., None], world, 0.0))


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 60), w=st.integers(1, 45), hidden=st.floats(0.0, 0.6),
       lead=st.booleans())
def test_the_circular_median_is_the_one_before_bit_for_bit(seed, n, w, hidden, lead):
    """Rows full and with gaps (NaN first, as a stream's first windows, or anywhere), ties, zeros, wraps."""
    rng = np.random.default_rng(seed)
    windows = _angles(rng, (n, w))
    if lead:  # a stream's first windows: the newest k estimates of each row, NaN before them
        k = rng.integers(0, w + 1, n)
        windows[np.arange(w)[None] < (w - k)[:, None]] = np.nan
    else:
        windows[rng.random((n, w)) < hidden] = np.nan
    with np.errstate(all="ignore"):
        assert same_bits(_circular_median(windows), Before.circular_median(windows))


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 200), w=st.integers(1, 95), hidden=st.floats(0.0, 0.5),
       cuts=st.lists(st.integers(0, 200), max_size=4))
def test_a_stream_and_a_recording_filter_as_before_bit_for_bit(seed, n, w, hidden, cuts):
    rng = np.random.default_rng(seed)
    h = _angles(rng, n)
    h[rng.random(n) < hidden] = np.nan
    new, old = HeadingFilter(w), Before.HeadingFilter(w)
    edges = [0, *sorted({min(c, n) for c in cuts}), n]
    with np.errstate(all="ignore"):
        for a, b in zip(edges, edges[1:]):
            assert same_bits(new.update_many(h[a:b]), old.update_many(h[a:b]))
        assert same_bits(smooth_heading(h, w), Before.smooth_heading(h, w))


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 150), w=st.integers(1, 95), hidden=st.floats(0.0, 0.5))
def test_a_frame_at_a_time_filters_as_before_bit_for_bit(seed, n, w, hidden):
    """HeadingFilter.update (one row: its median on floats) against the update before, frame by frame."""
    rng = np.random.default_rng(seed)
    h = _angles(rng, n)
    h[rng.random(n) < hidden] = np.nan
    new, old = HeadingFilter(w), Before.HeadingFilter(w)
    with np.errstate(all="ignore"):
        for x in h:
            assert same_bits(new.update(x), old.update(x))


@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**31), name=st.sampled_from(sorted(BODIES)), n=st.integers(1, 150),
       turn=st.sampled_from([0.0, 0.02, 0.3]), hidden=st.sampled_from([0.0, 0.0, 0.1, 0.5]),
       bad=st.sampled_from([0.0, 0.0, 0.02]), zeros=st.booleans(), window=st.integers(0, 40),
       smooth=st.sampled_from(["stream", "recording", "none"]))
def test_root_relative_is_the_transform_before_bit_for_bit(seed, name, n, turn, hidden, bad, zeros, window, smooth):
    """Poses, visibility, root and heading: every percept the transform makes, as before, byte for byte."""
    rng = np.random.default_rng(seed)
    body = BODIES[name]
    world, visible = frames(name, rng, n, turn=turn, hidden=hidden, bad=bad, zeros=zeros)
    given_visible = None if rng.random() < 0.3 else visible
    smoothers = {"stream": (HeadingFilter(window), Before.HeadingFilter(window).update_many, (window, False)),
                 "recording": (RecordingFacing(window), lambda h: Before.smooth_heading(h, window), (window, True)),
                 "none": (None, None, None)}[smooth]
    with np.errstate(all="ignore"):
        got = root_relative(world, given_visible, body, smoothers[0])
        want = Before.root_relative(world, given_visible, body, smoothers[1], smoothers[2])
        assert all(same_bits(g, e) for g, e in zip(got, want))
        one = rng.integers(n)  # one frame on its own, and the public to_root_relative with and without a heading
        for frame in (world[one], world[one : one + 1], world):
            mask = visible[one] if frame.ndim == 2 else visible[: len(frame)]
            assert all(same_bits(g, e) for g, e in zip(to_root_relative(frame, mask, body),
                                                         Before.to_root_relative(frame, mask, body)))
        heading = rng.uniform(-4, 4, n)
        assert all(same_bits(g, e) for g, e in zip(to_root_relative(world, visible, body, heading),
                                                     Before.to_root_relative(world, visible, body, heading)))


@pytest.mark.parametrize("name", sorted(BODIES))
def test_motion_capture_percepts_are_the_ones_before_whatever_the_blocks(name):
    """The perception as the watching loop calls it (reset, then blocks of frames) gives the poses and visibility
    root_relative gave before, with the running median before; one frame at a time (perceive_pose, as a world's
    step) every percept the update before gave."""
    rng = np.random.default_rng(7)
    world, visible = frames(name, rng, 400, turn=0.05, hidden=0.05, bad=0.01, zeros=True)
    body, fps = BODIES[name], 30.0
    window = round(MotionCapture().params["facing_window"] * fps)
    want_pose, want_mask, _, want_heading = Before.root_relative(world, visible, body,
                                                                 Before.HeadingFilter(window).update_many,
                                                                 (window, False))
    seen = visible & np.isfinite(world).all(axis=-1)
    stream_votes = votes(marker_behind(np.where(seen[..., None], world, 0.0), seen, body), window, False)
    perception = MotionCapture()
    perception.reset(fps)
    got = [perception.perceive_poses(world[a:b], visible[a:b], body, None) for a, b in ((0, 1), (1, 95), (95, 400))]
    assert same_bits(np.concatenate([p for p, _ in got]), want_pose)
    assert same_bits(np.concatenate([m for _, m in got]), want_mask)
    perception.reset(fps)
    before = Before.HeadingFilter(window)
    for f in range(0, 120):  # one frame at a time: HeadingFilter.update, as a world's step perceives
        percept = perception.perceive_pose(world[f], visible[f], body, f / fps)
        old_pose, old_mask, old_root, old_heading = Before.root_relative(world[f][None], visible[f][None], body,
                                                                         lambda h: np.array([before.update(h[0])]),
                                                                         stream_votes[f : f + 1])
        assert same_bits(percept.pose, old_pose[0]) and same_bits(percept.visible, old_mask[0])
        assert same_bits(percept.root, old_root[0]) and same_bits(np.float64(percept.heading), old_heading[0])
