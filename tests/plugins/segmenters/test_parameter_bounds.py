"""Every duration a segmenter takes is bounded where it is declared (``seconds=True``, ``toolkit.params.MAX_SECONDS``),
so that the largest value accepted runs and a larger one is a parameter error naming the key before the plugin runs
(issue 38: ``--set segmenter.floor=1e308`` was an ``OverflowError`` inside the plugin, blamed on it)."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from tests.conftest import write_stick_clip, write_stick_profile
from toolkit.params import MAX_MAGNITUDE, MAX_SECONDS, flat_parameters

SEGMENTERS = ("hub-threshold", "ruptures", "velocity-direction")


def _seconds_parameters() -> list[tuple[str, str, float]]:
    """(segmenter, key path, the parameter) of every duration the segmenters declare."""
    from toolkit import create_plugin_manager

    registry = create_plugin_manager(autoload=False).registry
    out = []
    for name in SEGMENTERS:
        for path, p in flat_parameters(registry.get("segmenter", name).parameters):
            if p.seconds:
                out.append((name, ".".join(path), p))
    return out


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """A stick figure's profile, a repertoire of one bob and a stream of two bobs with rests between (30 fps)."""
    root = tmp_path_factory.mktemp("bounds")
    profile = write_stick_profile(root)
    t = np.linspace(0.0, 1.0, 31)
    stand = np.array([[0, 1, 0], [0, 1.6, 0.1], [0.1, 0.5, 0], [-0.1, 0.5, 0], [0.3, 1.0, 0], [0.1, 0, 0],
                      [-0.1, 0, 0]], float)
    bob = stand[None] + np.sin(np.pi * t)[:, None, None] * np.array([0.0, -0.2, 0.0])
    rest = np.repeat(stand[None], 20, axis=0)
    write_stick_clip(root / "repertoire" / "bob.bvh", bob)
    write_stick_clip(root / "stream.bvh", np.concatenate([rest, bob, rest, bob, rest]))
    return root, profile


def _observe(recordings, segmenter: str, key: str, value: str) -> tuple[int, str]:
    from likeme.cli import main

    root, profile = recordings
    args = ["observe", "--body", str(profile), "--repertoire", str(root / "repertoire"), "--segmenter", segmenter,
            "--set", f"segmenter.{key}={value}", str(root / "stream.bvh")]
    if key.startswith("rest."):  # the rest tables apply with the demonstrator's own rest
        args[-1:-1] = ["--set", "segmenter.reference=rest" if segmenter == "hub-threshold" else "segmenter.end=rest"]
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(args)
        except SystemExit as exc:
            status = exc.code
    return status, err.getvalue()


def test_every_segmenter_declares_its_durations():
    found = {(name, key) for name, key, _ in _seconds_parameters()}
    assert {("hub-threshold", "floor"), ("hub-threshold", "max_gap"), ("ruptures", "window"),
            ("velocity-direction", "memory"), ("velocity-direction", "max_movement")} <= found
    assert all(p.maximum == MAX_SECONDS for _, _, p in _seconds_parameters())


@pytest.mark.parametrize("segmenter, key, p", _seconds_parameters())
def test_the_longest_duration_accepted_runs(recordings, monkeypatch, segmenter, key, p):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    status, err = _observe(recordings, segmenter, key, repr(p.maximum))
    assert status == 0, err


@pytest.mark.parametrize("segmenter, key, p", _seconds_parameters())
@pytest.mark.parametrize("value", ["1e308", "3600.5"])
def test_a_longer_duration_is_a_parameter_error_naming_the_key(recordings, monkeypatch, segmenter, key, p, value):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    status, err = _observe(recordings, segmenter, key, value)
    assert status == 1 and err.count("\n") == 1, err
    assert f"key --set.segmenter.{key}: value {float(value)!r} out of range" in err
    assert f"expected a number in [{p.minimum:g}, 3600]" in err
    assert "failed in" not in err  # the plugin never ran


@pytest.mark.parametrize("segmenter, key", [("hub-threshold", "threshold"), ("ruptures", "penalty"),
                                            ("velocity-direction", "rest_speed")])
def test_a_number_beyond_any_parameter_is_refused_by_key(recordings, monkeypatch, segmenter, key):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    status, err = _observe(recordings, segmenter, key, "1e308")
    assert status == 1 and err.count("\n") == 1, err
    assert f"key --set.segmenter.{key}: value 1e+308 too large" in err and f"{MAX_MAGNITUDE:g}]" in err
    status, err = _observe(recordings, segmenter, key, repr(MAX_MAGNITUDE))
    assert status == 0, err
