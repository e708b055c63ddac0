"""View ``imitation``: a demonstration and the observer's imitation side by side (B&B §5.3, K&G §4.4)."""

from __future__ import annotations

import numpy as np
import pytest

from likeme.cli import main
from plugins.bench.data import make_data
from plugins.views.imitation import side_by_side
from toolkit import create_plugin_manager


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    return make_data(create_plugin_manager(), tmp_path_factory.mktemp("imitation-view"), streams=1, per_stream=2)


def test_side_by_side_puts_both_on_the_floor_apart():
    rng = np.random.default_rng(0)
    demo = rng.normal(size=(20, 5, 3)) * 0.2 + np.array([0.0, 1.0, 0.0])
    imitation = demo + np.array([0.3, 0.5, 0.0])  # somewhere else, on another floor
    a, b, view = side_by_side(demo, imitation, (demo[..., 1].min(), imitation[..., 1].min()), facing=0.0)
    assert a[..., 1].min() == pytest.approx(0.0) and b[..., 1].min() == pytest.approx(0.0)
    across = np.array([view[2], 0.0, -view[0]])
    assert (a @ across).max() < (b @ across).min()  # beside each other as the camera sees them, not overlapping
    assert view @ np.array([0.0, 0.0, 1.0]) == pytest.approx(-1.0)  # standing still: seen from the front


def test_a_traveller_is_followed_along_the_travel():
    t = np.linspace(0.0, 5.0, 50)
    demo = np.zeros((50, 3, 3)) + np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 1.7, 0.0]])
    demo[..., 0] += t[:, None]  # walks 5 m along x
    a, b, view = side_by_side(demo, demo.copy(), (0.0, 0.0), facing=0.0)
    assert abs(view[0]) == pytest.approx(1.0)
    assert np.abs(b[..., 2] - a[..., 2]).min() > 0.5


def test_show_draws_a_written_imitation_beside_the_demonstration(generated, tmp_path, capsys):
    stream = generated / "streams" / "stream_1.bvh"
    body, repertoire = str(generated / "profile.toml"), str(generated / "repertoire")
    written = tmp_path / "imitation.bvh"
    assert main(["imitate", "--body", body, "--repertoire", repertoire, str(stream), "--out", str(written)]) == 0
    capsys.readouterr()
    assert main(["show", "--body", body, "--repertoire", repertoire, str(stream), "--view", "imitation",
                 "--set", f"imitation={written}", "--set", "every=40", "--set", "width=96", "--set", "height=64",
                 "--set", 'formats=["png", "gif"]', "--out", str(tmp_path / "pictures")]) == 0
    folder = tmp_path / "pictures" / "stream_1-imitation"
    frames = sorted(folder.glob("frame_*.png"))
    n = len(np.arange(0, load_frames(body, stream), 40))
    assert len(frames) == n and (folder / "imitation.gif").stat().st_size > 0
    import imageio.v2 as imageio

    image = imageio.imread(frames[len(frames) // 2])
    assert image.shape[:2] == (64, 96) and len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 3


def test_show_imitates_itself_and_names_a_wrong_imitation(generated, tmp_path, capsys):
    stream = generated / "streams" / "stream_1.bvh"
    body, repertoire = str(generated / "profile.toml"), str(generated / "repertoire")
    assert main(["show", "--body", body, "--repertoire", repertoire, str(stream), "--view", "imitation",
                 "--set", "every=60", "--set", "width=64", "--set", "height=64", "--set", 'formats=["png"]',
                 "--out", str(tmp_path)]) == 0
    assert sorted((tmp_path / "stream_1-imitation").glob("frame_*.png"))
    other = generated / "repertoire" / "jump" / "max.bvh"
    assert main(["show", "--body", body, "--repertoire", repertoire, str(stream), "--view", "imitation",
                 "--set", f"imitation={other}", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "max.bvh" in err and "the imitation of this recording" in err


def load_frames(body, path):
    from toolkit.recordings.profile import load_profile

    return load_profile(body).read(path).n_frames
