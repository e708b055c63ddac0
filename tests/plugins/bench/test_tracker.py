"""``--jitter M``: every recording a benchmark reads, read with a tracker's jitter (plugins.bench.tracker)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from plugins.bench.data import make_data
from plugins.bench.mocap import cell
from plugins.bench.tracker import Jittered, jittered
from plugins.lib.clip_repertoire import load_clip_repertoire
from toolkit.manager import create_plugin_manager
from toolkit.recordings.profile import load_profile


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("tracker"), seed=4, streams=1, per_stream=2)


def test_the_jitter_is_gaussian_of_the_given_size_and_the_same_for_a_file_whatever_reads_it(generated):
    profile = load_profile(generated / "profile.toml")
    clip = generated / "repertoire" / "bow" / "max.bvh"
    clean = profile.read(clip).positions
    noisy = jittered(profile, 0.01, seed=2)
    a, b = noisy.read(clip).positions, noisy.read(clip).positions
    np.testing.assert_array_equal(a, b)  # its and its folder's names and the seed, not the order of reading
    assert np.std(a - clean) == pytest.approx(0.01, rel=0.05) and abs(np.mean(a - clean)) < 0.001
    assert not np.array_equal(jittered(profile, 0.01, seed=3).read(clip).positions, a)
    other = noisy.read(generated / "repertoire" / "nod" / "max.bvh").positions - profile.read(
        generated / "repertoire" / "nod" / "max.bvh").positions
    assert not np.allclose(other[: len(a)], (a - clean)[: len(other)])  # each file its own noise
    assert jittered(profile, 0.0) is profile


def test_the_jittered_profile_is_the_profile_everywhere_else(generated):
    profile = load_profile(generated / "profile.toml")
    noisy = jittered(profile, 0.02)
    assert isinstance(noisy, Jittered) and noisy.body == profile.body and noisy.joints == profile.joints
    assert isinstance(noisy.for_file(generated / "demos" / "bow" / "morris_1.0.bvh"), Jittered)
    fields = {f.name for f in dataclasses.fields(profile)}
    assert all(getattr(noisy, f) == getattr(profile, f) for f in fields if f != "files")
    # the repertoire an observer is composed from is read through it too
    rep = load_clip_repertoire(generated / "repertoire", noisy)
    clean = load_clip_repertoire(generated / "repertoire", profile)
    assert len(rep.clips) == len(clean.clips)
    assert not np.allclose(rep.clips[0].motion.world, clean.clips[0].motion.world)


def test_a_benchmark_run_in_another_process_reads_the_same_jitter(generated):
    spec = {"benchmark": "recognition", "body": str(generated / "profile.toml"), "repertoire": str(
        generated / "repertoire"), "demos": str(generated / "demos"), "matchers": ["dtw"], "jitter": 0.05}
    noisy, again, clean = cell(spec), cell(spec), cell({**spec, "jitter": 0.0})
    answers = lambda result: [(r["item"], r["recognised"]) for r in result["items"]]  # noqa: E731
    assert answers(noisy) == answers(again)
    assert [r["score"] for r in noisy["items"]] != [r["score"] for r in clean["items"]]


def test_a_tracker_loses_each_joint_for_its_share_of_frames_in_short_gaps(generated):
    from plugins.bench.tracker import GAP

    profile = load_profile(generated / "profile.toml")
    clip = generated / "streams" / "stream_1.bvh"
    lost = ~np.isfinite(jittered(profile, 0.0, dropout=0.1).read(clip).positions).all(axis=-1)
    fps = profile.read(clip).fps
    assert np.allclose(lost.mean(axis=0), 0.1, atol=0.04)  # each joint on its own
    for part in range(lost.shape[1]):
        edges = np.flatnonzero(np.diff(np.r_[0, lost[:, part].astype(int), 0]))
        lengths = edges[1::2] - edges[::2]
        assert lengths.min() >= 1 and np.median(lengths) <= round(GAP[1] * fps) + 1
    assert not np.array_equal(lost[:, 0], lost[:, 1])
