"""Views of one's own recordings (``likeme show --body PROFILE FILE ... --view NAME``) and the benchmark pictures.

Each picture is checked as numbers before it is rendered, as matplotlib's own tests do: how many spans the
timeline has and where, what they are labelled, that no two labels overlap in display coordinates and that every
label lies inside its axes and every tick label inside the figure; then the PNG is written. The recordings are the
project's own, written by ``make_data`` into a temporary folder.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plugins.bench.data import make_data, read_segments
from toolkit import create_plugin_manager
from toolkit.cli import main

matplotlib = pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    pm = create_plugin_manager(autoload=False, trace=False)
    return make_data(pm, tmp_path_factory.mktemp("generated"), seed=5, streams=2, per_stream=4)


@pytest.fixture
def figures(monkeypatch):
    """Every figure saved by :func:`plugins.views.plotting.save_figure`, as it was saved."""
    import plugins.views.plotting as plotting

    saved = []
    real = plotting.save_figure

    def keep(fig, out):
        path = real(fig, out)
        saved.append(fig)
        return path

    for module in ("plugins.views.hub_signal", "plugins.views.speed_profile", "plugins.views.prediction_error"):
        monkeypatch.setattr(f"{module}.save_figure", keep)
    monkeypatch.setattr(plotting, "save_figure", keep)
    return saved


def _labels(ax):
    """The visible span labels of an axis (:func:`plugins.views.plotting.span_label`), with their pixel boxes."""
    from plugins.views.plotting import SPAN_LABEL

    renderer = ax.figure.canvas.get_renderer()
    return [(t, t.get_window_extent(renderer)) for t in ax.texts if t.get_gid() == SPAN_LABEL and t.get_visible()]


def _assert_readable(fig):
    """No two span labels of an axis overlap, each lies inside its axes and its span; tick labels and titles lie
    inside the figure."""
    from plugins.views.plotting import FREE_LABEL

    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    for ax in fig.axes:
        labels = _labels(ax)
        for k, (text, box) in enumerate(labels):
            assert ax.bbox.x0 - 0.5 <= box.x0 and box.x1 <= ax.bbox.x1 + 0.5, text.get_text()
            (s0, _), (s1, _) = ax.transData.transform([(text.likeme_span[0], 0), (text.likeme_span[1], 0)])
            assert min(s0, s1) - 0.5 <= box.x0 and box.x1 <= max(s0, s1) + 0.5, text.get_text()
            for other, obox in labels[k + 1 :]:
                apart = box.x1 <= obox.x0 + 0.5 or obox.x1 <= box.x0 + 0.5 or box.y1 <= obox.y0 or obox.y1 <= box.y0
                assert apart, f"{text.get_text()!r} overlaps {other.get_text()!r}"
        free = [t.get_window_extent(renderer) for t in ax.texts if t.get_gid() == FREE_LABEL and t.get_visible()]
        for k, box in enumerate(free):
            assert ax.bbox.x0 <= box.x0 and box.x1 <= ax.bbox.x1 and ax.bbox.y0 <= box.y0 and box.y1 <= ax.bbox.y1
            assert not any(box.overlaps(other) for other in free[k + 1 :])
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        drawn = [t for t in ax.get_xticklabels() if x0 - 1e-9 <= t.get_position()[0] <= x1 + 1e-9]  # in view
        drawn += [t for t in ax.get_yticklabels() if y0 - 1e-9 <= t.get_position()[1] <= y1 + 1e-9]
        for tick in [*drawn, ax.title, ax._left_title]:
            if tick.get_visible() and tick.get_text():
                box = tick.get_window_extent(renderer)
                assert page.x0 - 0.5 <= box.x0 and box.x1 <= page.x1 + 0.5, tick.get_text()
                assert page.y0 - 0.5 <= box.y0 and box.y1 <= page.y1 + 0.5, tick.get_text()


def _spans(ax, lane):
    """The (start, end) seconds of the spans an axis has between the axes fractions ``lane`` (bottom, top)."""
    out = []
    for patch in ax.patches:
        box = patch.get_path().get_extents(patch.get_patch_transform())
        y0, y1 = box.y0, box.y1  # axvspan: x in data, y in axes fraction
        if abs(y0 - lane[0]) < 1e-6 and abs(y1 - lane[1]) < 1e-6:
            out.append((round(box.x0, 6), round(box.x1, 6)))
    return sorted(out)


# -- fitting labels ------------------------------------------------------------------------------------------


def test_labels_are_shortened_to_their_span_hidden_where_nothing_fits_and_titles_kept_on_the_page(tmp_path):
    from plugins.views.plotting import ELLIPSIS, blank, save_figure, span_label

    fig = blank(600, 200)
    ax = fig.subplots()
    ax.set_xlim(0, 10)
    spans = [(0.0, 4.0, "wide enough"), (4.0, 4.9, "a very long movement name"), (4.9, 5.0, "tiny"),
             (9.5, 12.0, "runs past the end of the axis")]
    labels = [span_label(ax, a, b, 0.5, text) for a, b, text in spans]
    ax.set_title("a title far too long for a picture six hundred pixels wide " * 3, loc="left")
    save_figure(fig, tmp_path / "labels.png")
    assert labels[0].get_text() == "wide enough" and labels[0].get_visible()
    assert labels[1].get_text().endswith(ELLIPSIS) and "a very long movement name".startswith(labels[1].get_text()[:-1])
    assert not labels[2].get_visible()  # 6 pixels: not one letter
    assert labels[3].get_visible() and labels[3].get_position()[0] == pytest.approx(9.75)  # centred in what shows
    assert ax._left_title.get_text().endswith(ELLIPSIS)
    _assert_readable(fig)
    assert (tmp_path / "labels.png").stat().st_size > 1000


# -- views of recordings -------------------------------------------------------------------------------------


def test_the_hub_signal_of_a_recording_shows_its_true_segments_and_what_observe_finds(data, tmp_path, capsys, figures):
    stream = data / "streams" / "stream_1.bvh"
    common = ["--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire")]
    assert main(["observe", *common, str(stream), "--json"]) == 0
    observed = json.loads(capsys.readouterr().out)[0]
    fps = observed["fps"]
    out = tmp_path / "pictures"
    assert main(["show", *common, str(stream), "--view", "hub-signal", "--out", str(out), "--set", "width=900",
                 "--set", "height=500"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out / 'stream_1-hub-signal.png'}"
    fig, = figures
    top = fig.axes[0]
    truth = read_segments(stream.with_suffix(".segments.csv"))
    assert np.allclose(_spans(top, (0.55, 0.95)), [(a / fps, b / fps) for a, b, _ in truth], atol=1e-3)
    found = observed["segments"]
    assert np.allclose(_spans(top, (0.05, 0.45)), [(s["start_s"], s["end_s"]) for s in found], atol=2e-3)
    words = [t.likeme_text for t in top.texts if t.get_gid()]
    assert words == [m for _, _, m in truth] + [s["movement"] for s in found]
    assert [t.get_text() for t in top.get_yticklabels()] == ["found", "performed"]
    _assert_readable(fig)
    assert (out / "stream_1-hub-signal.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_recording_without_a_repertoire_is_segmented_by_the_view_s_segmenter_and_left_unnamed(data, tmp_path,
                                                                                                 figures, capsys):
    stream = data / "streams" / "stream_2.bvh"
    out = tmp_path / "speed.png"
    assert main(["show", "--body", str(data / "profile.toml"), str(stream), "--view", "speed-profile", "--out",
                 str(out), "--set", "width=1000", "--set", "height=600"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    fig, = figures
    top, speed = fig.axes[:2]
    trajectories = fig.axes[2:]
    assert len(trajectories) == 3  # the three parts that travel most, of the recording's eleven
    found = _spans(top, (0.05, 0.45))
    assert found and all(b > a for a, b in found)
    assert not any(t.get_gid() and t.get_position()[1] < 0.5 for t in top.texts)  # no matcher: nothing recognised
    assert "speed of the fastest part" in speed.get_legend().texts[0].get_text()
    _assert_readable(fig)
    for ax in trajectories:  # narrow panels: their tick labels do not run into one another
        lo, hi = sorted(ax.get_xlim())
        boxes = sorted((t.get_window_extent(fig.canvas.get_renderer()) for t in ax.get_xticklabels()
                        if t.get_text() and lo <= t.get_position()[0] <= hi), key=lambda b: b.x0)
        assert all(a.x1 <= b.x0 for a, b in zip(boxes, boxes[1:]))
    assert out.stat().st_size > 1000


def test_the_prediction_error_of_a_recording_marks_each_commitment_and_keeps_its_notes_apart(data, tmp_path,
                                                                                              figures, capsys):
    stream = data / "streams" / "stream_1.bvh"
    assert main(["show", "--body", str(data / "profile.toml"), str(stream), "--repertoire", str(data / "repertoire"),
                 "--view", "prediction-error", "--out", str(tmp_path), "--set", "width=1000",
                 "--set", "height=500"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {tmp_path / 'stream_1-prediction-error.png'}"
    fig, = figures
    top, ax = fig.axes
    ticks = [line for line in top.lines if line.get_color() == "black"]  # a commitment before the segment ended
    commits = [line for line in ax.lines if line.get_color() == "black" and line.get_linestyle() == "-"
               and len(line.get_xdata()) == 2 and line.get_xdata()[0] == line.get_xdata()[1]]
    assert len(commits) == len(ticks) >= 1
    renderer = fig.canvas.get_renderer()
    assert ax.get_legend().get_window_extent(renderer).x0 >= ax.bbox.x1  # beside the plot, not over it
    _assert_readable(fig)


def test_show_draws_the_key_poses_of_several_recordings_in_one_picture(data, tmp_path, capsys):
    imageio = pytest.importorskip("imageio.v2")
    streams = sorted((data / "streams").glob("*.bvh"))
    assert main(["show", "--body", str(data / "profile.toml"), *map(str, streams), "--view", "body", "--out",
                 str(tmp_path), "--set", "keys=3", "--set", "width=400"]) == 0
    out = tmp_path / "recordings-body.png"
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    image = imageio.imread(out)[..., :3].astype(int)
    assert image.shape[1] == 400
    drawn = (np.abs(image - 255).sum(axis=-1) > 30).any(axis=1)
    bands = int((np.diff(np.concatenate([[0], drawn.astype(int)])) == 1).sum())
    assert bands >= 1 + len(streams)  # the hub pose, then a row of poses per recording


def test_the_body_frame_of_a_recording_faces_forward_with_its_feet_on_the_ground(data):
    from plugins.views.body import body_frame
    from toolkit.profile import load_profile

    profile = load_profile(data / "profile.toml")
    motion = profile.read(data / "streams" / "stream_1.bvh")
    poses = body_frame(motion, profile.body)
    parts = list(profile.body.parts)
    nose, root = poses[:, parts.index("nose")], poses[:, parts.index("root")]
    assert np.allclose(root[:, [0, 2]], 0.0, atol=1e-9)  # over the origin
    assert np.median(nose[:, 2]) > 0  # the nose in front (+z)
    feet = poses[:, [parts.index("left_foot"), parts.index("right_foot")], 1]
    assert np.median(feet) == pytest.approx(motion.positions[:, [parts.index("left_foot"),
                                                                  parts.index("right_foot")], 1].mean(), abs=0.05)


# -- benchmark pictures --------------------------------------------------------------------------------------


def test_the_segmentation_picture_is_a_timeline_of_true_and_found_segments_per_stream(data, tmp_path):
    from plugins.bench.metrics import match_segments
    from plugins.bench.mocap import segmentation
    from plugins.bench.plots import plot_result, timeline_figure
    from toolkit.profile import load_profile

    pm = create_plugin_manager(autoload=False, trace=False)
    result = segmentation(pm, load_profile(data / "profile.toml"), data / "streams", ["hub-threshold", "ruptures"],
                          repertoire=data / "repertoire")
    fig = timeline_figure(result)
    bars, *streams = fig.axes
    assert len(streams) == len(result["timelines"]) == 2
    assert [t.get_text() for t in bars.get_yticklabels()] == ["hub-threshold", "ruptures"]
    for ax, stream in zip(streams, sorted(result["timelines"], key=lambda t: t["item"])):
        assert [t.get_text() for t in ax.get_yticklabels()] == ["true", "hub-threshold", "ruptures"]
        truth = stream["truth"]
        assert sum(not p.get_hatch() for p in ax.patches) + sum(bool(p.get_hatch()) for p in ax.patches) == len(
            truth) + sum(len(f) for f in stream["found"].values())
        unmatched = sum(len(found) - len(match_segments([tuple(f) for f in found], [(a, b) for a, b, _ in truth]))
                        for found in stream["found"].values())
        assert sum(bool(p.get_hatch()) for p in ax.patches) == unmatched  # hatched: counts for no true movement
        assert [t.likeme_text for t in ax.texts if t.get_gid()] == [m for _, _, m in truth]
    plot_result(result, tmp_path / "segmentation.png")  # fits the labels, then writes
    _assert_readable(fig := timeline_figure(result))
    from plugins.views.plotting import fit_labels

    fit_labels(fig)
    _assert_readable(fig)
    assert (tmp_path / "segmentation.png").stat().st_size > 1000


def test_the_confusion_matrix_picture_writes_every_count_with_labels_and_a_colour_bar(tmp_path):
    from plugins.bench.plots import confusion_figure, plot_result
    from plugins.views.plotting import fit_labels

    labels = ["bow", "clap", "unknown", "wave"]
    confusion = [[3, 0, 0, 0], [1, 2, 0, 0], [0, 0, 0, 0], [0, 0, 1, 2]]
    result = {"benchmark": "recognition", "plugins": [{"plugin": "dtw", "accuracy": 7 / 9, "macro_f1": 0.7,
                                                       "items": 9, "labels": labels, "confusion": confusion}]}
    fig = confusion_figure(result)
    matrix, bar = fig.axes
    assert [t.get_text() for t in matrix.get_xticklabels()] == labels == [t.get_text() for t in
                                                                          matrix.get_yticklabels()]
    counts = {(int(round(t.get_position()[1])), int(round(t.get_position()[0]))): int(t.get_text())
              for t in matrix.texts}
    assert counts == {(i, j): c for i, row in enumerate(confusion) for j, c in enumerate(row) if c}
    assert bar.get_ylabel() == "clips" and bar.get_ylim() == (0, 3)
    fit_labels(fig)
    _assert_readable(fig)
    assert plot_result(result, tmp_path / "r.png").stat().st_size > 1000


def test_the_stream_picture_labels_each_found_segment_and_marks_the_wrong_ones():
    from plugins.bench.plots import FALSE, timeline_figure
    from plugins.views.plotting import fit_labels

    result = {"benchmark": "stream", "plugins": [{"plugin": "hub-threshold+dtw", "error_rate": 0.5}], "timelines": [
        {"item": "s.bvh", "frames": 300, "fps": 30.0, "truth": [[30, 120, "wave"], [150, 270, "bow"]],
         "found": {"hub-threshold+dtw": [[35, 115, "wave"], [155, 260, "clap"], [275, 290, "unknown"]]}}]}
    fig = timeline_figure(result)
    fit_labels(fig)
    _, ax = fig.axes
    labels = {t.likeme_text: t.get_color() for t in ax.texts if t.get_gid()}
    assert labels == {"wave": "black", "bow": "black", "clap": FALSE, "unknown": FALSE}
    assert [t.get_text() for t in ax.get_yticklabels()] == ["true", "hub-threshold+dtw"]
    assert not any(p.get_hatch() for p in ax.patches)  # every found segment is named: coloured, not hatched
    _assert_readable(fig)


def test_show_out_names_a_folder_or_a_file_and_the_picture_honours_the_umask(tmp_path, capsys):
    import os

    args = ["show", "max", "--view", "body", "--set", "keys=1", "--set", 'movements=["jump"]', "--set", "width=200"]
    old = os.umask(0o022)
    try:
        assert main([*args, "--out", str(tmp_path / "pictures")]) == 0
        assert main([*args, "--out", str(tmp_path / "max.png")]) == 0
    finally:
        os.umask(old)
    folder = tmp_path / "pictures" / "max-body.png"
    assert capsys.readouterr().out.split() == ["wrote", str(folder), "wrote", str(tmp_path / "max.png")]
    assert folder.is_file() and (tmp_path / "max.png").is_file()


def test_a_signal_picture_is_written_with_the_mode_the_umask_allows(tmp_path):
    import os

    from plugins.views.plotting import blank, save_figure

    fig = blank(200, 200)
    fig.subplots().plot([0, 1], [0, 1])
    old = os.umask(0o022)
    try:
        path = save_figure(fig, tmp_path / "p.png")
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == 0o644
