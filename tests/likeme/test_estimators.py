"""The scikit-learn style estimators (likeme.estimators) and repertoires built in memory, on generated data.

The same pipeline as ``likeme bench recognition|segmentation`` on the same clips must give the same answers; the
estimators must behave as scikit-learn estimators (clone, cross_val_score, GridSearchCV, get/set_params).
"""

from __future__ import annotations

import copy
import pickle

import joblib
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import sparse
from sklearn.exceptions import NotFittedError
from sklearn.utils import estimator_checks
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, LeaveOneGroupOut, cross_val_score

from plugins.bench.data import make_data
from plugins.bench.mocap import recognition, segmentation
from plugins.lib.clip_repertoire import clip_repertoire, load_clip_repertoire
from toolkit import ConfigError, create_plugin_manager
from likeme.estimators import (UNKNOWN, EstimatorInputError, MovementClassifier, MovementSegmenter, load_recordings,
                                load_streams, to_breakpoints)
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile

KEEP = ("bow", "clap", "kick", "nod", "point", "salute", "wave", "jump")
"""The movements the cross-validation tests use (a few, to stay quick)."""


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    dest = make_data(create_plugin_manager(), tmp_path_factory.mktemp("estimators"), streams=2, per_stream=3)
    return dest, load_profile(dest / "profile.toml")


@pytest.fixture(scope="module")
def performers(data):
    """Max's clips and Morris's demos of the KEEP movements, grouped by performer."""
    dest, profile = data
    motions, labels, groups = [], [], []
    for folder in ("repertoire", "demos"):
        m, y, g = load_recordings(dest / folder, profile, group=r"^([a-z]+)_?")
        keep = [i for i, label in enumerate(y) if label in KEEP]
        motions += [m[i] for i in keep]
        labels += [y[i] for i in keep]
        groups += [g[i] for i in keep]
    return motions, labels, groups


def test_memory_repertoire_is_the_folder_repertoire(data):
    dest, profile = data
    folder = load_clip_repertoire(dest / "repertoire", profile)
    motions, labels, _ = load_recordings(dest / "repertoire", profile)
    memory = clip_repertoire(motions, labels, profile)
    assert memory.folder is None and folder.folder == dest / "repertoire"
    np.testing.assert_array_equal(memory.hubs, folder.hubs)
    assert [c.movement for c in memory.clips] == [c.movement for c in folder.clips]
    for a, b in zip(memory.clips, folder.clips):
        np.testing.assert_array_equal(a.motion.positions, b.motion.positions)
    pm = create_plugin_manager()
    by_folder = compose_observer(pm, profile, dest / "repertoire")
    by_memory = compose_observer(pm, profile, memory)
    assert list(by_memory.motor.graph.nodes(data=True)) == list(by_folder.motor.graph.nodes(data=True))
    assert list(by_memory.motor.graph.edges) == list(by_folder.motor.graph.edges)
    np.testing.assert_array_equal(by_memory.motor.node_poses, by_folder.motor.node_poses)
    demos, _, _ = load_recordings(dest / "demos", profile)
    for motion in demos[::9]:
        a = Observer(by_folder, profile.body, motion.fps).classify(motion)
        b = Observer(by_memory, profile.body, motion.fps).classify(motion)
        assert (a.movement, a.match.confidence, a.decided_at) == (b.movement, b.match.confidence, b.decided_at)


def test_memory_repertoire_follows_the_motor_hub_settings(data):
    """A repertoire built with other hub settings than the motor system's is rebuilt with the motor's, as the
    folder would be read with them."""
    dest, profile = data
    motions, labels, _ = load_recordings(dest / "repertoire", profile)
    pm = create_plugin_manager()
    settings = {"motor": {"hub_radius": 0.2, "hub_share": 0.5}}
    by_folder = compose_observer(pm, profile, dest / "repertoire", settings=settings)
    by_memory = compose_observer(pm, profile, clip_repertoire(motions, labels, profile), settings=settings)
    np.testing.assert_array_equal(by_memory.motor.clips.hubs, by_folder.motor.clips.hubs)
    assert by_memory.motor.clips.hub_radius == 0.2


def test_memory_repertoire_and_clips_folder_together_is_an_error(data):
    dest, profile = data
    motions, labels, _ = load_recordings(dest / "repertoire", profile)
    with pytest.raises(ConfigError, match="clips given twice"):
        compose_observer(create_plugin_manager(), profile, clip_repertoire(motions, labels, profile),
                         settings={"motor": {"clips": str(dest / "repertoire")}})


@pytest.mark.parametrize("matcher", ["path-search", "dtw", "forward-model"])
def test_classifier_answers_as_bench_recognition(data, matcher):
    """fit on the repertoire folder's clips, predict the demos: the answers and the accuracy of
    ``likeme bench recognition`` on the same folders, item by item."""
    dest, profile = data
    bench = recognition(create_plugin_manager(), profile, dest / "repertoire", dest / "demos", [matcher])
    X, y, _ = load_recordings(dest / "repertoire", profile)
    Xd, yd, _ = load_recordings(dest / "demos", profile)
    clf = MovementClassifier(profile, matcher=matcher).fit(X, y)
    predicted = clf.predict(Xd)
    assert list(predicted) == [row["recognised"] for row in bench["items"]]
    assert clf.score(Xd, yd) == pytest.approx(bench["plugins"][0]["accuracy"])
    assert clf.score(Xd, yd) > 0.8
    assert list(clf.classes_) == sorted(set(y))
    scores = clf.decision_function(Xd)
    assert scores.shape == (len(Xd), len(clf.classes_))
    confidence = [row["confidence"] for row in bench["items"]]
    np.testing.assert_allclose(scores.max(axis=1), confidence, atol=1e-4)
    answered = predicted != UNKNOWN
    assert (clf.classes_[scores[answered].argmax(axis=1)] == predicted[answered]).all()


def test_arrays_are_motions_at_fps(data):
    dest, profile = data
    X, y, _ = load_recordings(dest / "repertoire", profile)
    arrays = [m.positions for m in X]
    a = MovementClassifier(profile).fit(X, y).predict(X[:6])
    b = MovementClassifier(profile, fps=30.0).fit(arrays, y).predict(arrays[:6])
    assert list(a) == list(b)
    assert (a == np.array(y[:6], dtype=object)).all()


def test_labels_that_are_numbers_come_back_as_numbers(data):
    dest, profile = data
    X, y, _ = load_recordings(dest / "repertoire", profile)
    names = sorted(set(y))
    numbers = np.array([names.index(label) for label in y])
    clf = MovementClassifier(profile, unknown=-1).fit(X, numbers)
    assert clf.classes_.tolist() == list(range(len(names)))
    predicted = clf.predict(X[:5])
    assert predicted.tolist() == numbers[:5].tolist() and predicted.dtype.kind == "i"
    assert clf.score(X[:5], numbers[:5]) == 1.0
    rejecting = clone(clf).set_params(matcher__comparison="poses", matcher__decision="distance",
                                      matcher__distance__max_distance=1e-9).fit(X, numbers)
    assert rejecting.predict(X[:3]).tolist() == [-1, -1, -1]
    with pytest.raises(EstimatorInputError, match="the label -1"):
        clf.fit(X[:2], [0, -1])


def test_segmenter_scores_as_bench_segmentation(data):
    dest, profile = data
    bench = segmentation(create_plugin_manager(), profile, dest / "streams", ["hub-threshold"])
    streams, truth = load_streams(dest / "streams", profile)
    seg = MovementSegmenter(profile).fit(streams)
    found = seg.predict(streams)
    assert [len(f) for f in found] == [row["found"] for row in bench["items"]]
    assert seg.score(streams, truth) == pytest.approx(bench["plugins"][0]["f1"])
    for spans, motion in zip(found, streams):
        assert all(0 <= a < b <= motion.n_frames for a, b in spans)
        assert all(spans[i][1] <= spans[i + 1][0] for i in range(len(spans) - 1))
    breakpoints = seg.predict_breakpoints(streams)
    assert [b[-1] for b in breakpoints] == [m.n_frames for m in streams]
    assert breakpoints[0] == to_breakpoints(found[0], streams[0].n_frames)


def test_segmenter_with_a_repertoire_given(data):
    """Hubs from a repertoire given as (motions, labels) or built: the same segments either way."""
    dest, profile = data
    streams, truth = load_streams(dest / "streams", profile)
    X, y, _ = load_recordings(dest / "repertoire", profile)
    a = MovementSegmenter(profile, repertoire=(X, y)).fit(streams).predict(streams)
    b = MovementSegmenter(profile, repertoire=clip_repertoire(X, y, profile)).fit(streams).predict(streams)
    assert a == b and all(a)


def test_grid_search_over_a_segmenter_parameter(data):
    """A threshold above every movement's distance from the hub finds nothing (F1 0); the search keeps the other.
    (The template's hub-threshold measures in body sizes: its ``body.threshold``.)"""
    dest, profile = data
    streams, truth = load_streams(dest / "streams", profile)
    search = GridSearchCV(MovementSegmenter(profile), {"segmenter__body__threshold": [0.1, 50.0]}, cv=2)
    search.fit(streams, truth)
    assert search.best_params_ == {"segmenter__body__threshold": 0.1}
    assert list(search.cv_results_["mean_test_score"]) == [1.0, 0.0]
    assert search.best_estimator_.predict(streams[:1])[0]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(0, 1000), max_size=12), st.integers(1, 2000))
def test_to_breakpoints_is_ruptures_form(cuts, n):
    cuts = sorted(set(c for c in cuts if c < n))
    segments = list(zip(cuts[::2], cuts[1::2]))
    b = to_breakpoints(segments, n)
    assert b[-1] == n and b == sorted(set(b))
    assert {e for s in segments for e in s if 0 < e < n} == set(b[:-1])


def test_cross_val_score_across_performers(performers, data):
    """Leave one performer out: the scores are those of fitting on one performer and scoring on the other."""
    _, profile = data
    X, y, groups = performers
    assert sorted(set(groups)) == ["max", "morris"]
    scores = cross_val_score(MovementClassifier(profile), X, y, groups=groups, cv=LeaveOneGroupOut())
    expected = []
    for held in ("max", "morris"):
        train = [i for i, g in enumerate(groups) if g != held]
        test = [i for i, g in enumerate(groups) if g == held]
        clf = MovementClassifier(profile).fit([X[i] for i in train], [y[i] for i in train])
        expected.append(clf.score([X[i] for i in test], [y[i] for i in test]))
    np.testing.assert_allclose(scores, expected)
    assert min(scores) > 0.7


def test_grid_search_over_a_plugin_parameter(performers, data):
    """The papers' max_distance far below the noise rejects every demo of a movement known from one take
    ("unknown"); the search finds the working decision, the template's calibrated one."""
    _, profile = data
    X, y, groups = performers
    search = GridSearchCV(MovementClassifier(profile), {"matcher__decision": ["distance", "calibrated"],
                                                        "matcher__comparison": ["poses"],
                                                        "matcher__distance__max_distance": [0.0005]},
                          cv=LeaveOneGroupOut())
    search.fit(X, y, groups=groups)
    assert search.best_params_["matcher__decision"] == "calibrated"
    results = search.cv_results_  # split 1 holds Morris out: the observer knows Max's one take of each
    assert results["split1_test_score"][0] == 0.0 < results["split1_test_score"][1]
    assert results["mean_test_score"][0] < results["mean_test_score"][1]
    assert search.best_estimator_.get_params()["matcher__decision"] == "calibrated"
    assert search.best_estimator_.settings["matcher"]["decision"] == "calibrated"


def test_clone_keeps_plugin_parameters(data):
    _, profile = data
    clf = MovementClassifier(profile, matcher="dtw").set_params(matcher__window=0.3)
    copy = clone(clf)
    assert copy is not clf and copy.get_params() == clf.get_params()
    assert copy.get_params()["matcher__window"] == 0.3
    assert not hasattr(copy, "character_")


PARAMS = {"matcher__beam__k": st.integers(1, 20), "matcher__beam__max_skip": st.integers(1, 5),
          "matcher__calibrated__known_rejected": st.floats(0.0, 1.0), "matcher__candidates": st.integers(0, 10),
          "segmenter__threshold": st.floats(0.001, 0.5), "motor__hub_radius": st.floats(0.0, 0.5),
          "matcher": st.just("path-search"), "fps": st.floats(1.0, 240.0)}
PARAM_SETS = st.dictionaries(st.sampled_from(sorted(PARAMS)), st.none()).flatmap(
    lambda keys: st.fixed_dictionaries({k: PARAMS[k] for k in keys}))
"""Some of PARAMS, each with a value drawn."""


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(PARAM_SETS)
def test_get_set_params_round_trip(data, params):
    _, profile = data
    clf = MovementClassifier(profile).set_params(**params)
    got = clf.get_params()
    for key, value in params.items():
        assert got[key] == value
    again = MovementClassifier(profile).set_params(**got)  # every plugin parameter now written in settings
    plugin = {k: v for k, v in got.items() if k != "settings"}
    assert {k: v for k, v in again.get_params().items() if k != "settings"} == plugin
    assert clone(clf).get_params() == got


SEGMENTER_PARAMS = {"segmenter__threshold": st.floats(0.0, 1.0), "segmenter__min_duration": st.floats(0.0, 2.0),
                    "segmenter__release": st.floats(0.0, 1.0), "segmenter": st.just("hub-threshold")}


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.dictionaries(st.sampled_from(sorted(SEGMENTER_PARAMS)), st.none()).flatmap(
    lambda keys: st.fixed_dictionaries({k: SEGMENTER_PARAMS[k] for k in keys})))
def test_segmenter_get_set_params_round_trip(data, params):
    _, profile = data
    seg = MovementSegmenter(profile).set_params(**params)
    got = seg.get_params()
    assert {k: got[k] for k in params} == params
    assert clone(seg).get_params() == got


def test_plugin_parameters_follow_the_plugin(data):
    _, profile = data
    clf = MovementClassifier(profile)
    assert "matcher__beam__k" in clf.get_params()
    clf.set_params(matcher="dtw")
    params = clf.get_params()
    assert "matcher__beam__k" not in params and "matcher__window" in params
    assert "motor__clips" not in params and "motor__profile" not in params
    seg = MovementSegmenter(profile, segmenter="velocity-direction")
    assert not any(k.startswith("matcher__") for k in seg.get_params())
    assert any(k.startswith("segmenter__") for k in seg.get_params())


def test_errors(data):
    dest, profile = data
    X, y, _ = load_recordings(dest / "repertoire", profile)
    clf = MovementClassifier(profile)
    with pytest.raises(EstimatorInputError, match="31 motions and 30 labels"):
        clf.fit(X, y[:-1])
    with pytest.raises(ValueError, match=r"X\[1\] has shape \(10, 3\)"):
        clf.fit([X[0], np.zeros((10, 3))], y[:2])
    with pytest.raises(EstimatorInputError, match="X is one motion"):
        clf.fit(X[0], y[:1])
    with pytest.raises(EstimatorInputError, match="the label 'unknown'"):
        clf.fit(X[:2], ["bow", UNKNOWN])
    with pytest.raises(EstimatorInputError, match="without '#'"):
        clf.fit(X[:2], ["bow", "bow#2"])
    with pytest.raises(EstimatorInputError) as err:
        clf.set_params(matcher__kk=3)
    assert "unknown parameter 'matcher__kk' of matcher plugin 'path-search'" in str(err.value)
    assert "matcher__beam__k" in err.value.available and "segmenter__threshold" in err.value.available
    with pytest.raises(EstimatorInputError, match="unknown parameter 'nosuch__k'"):
        clf.set_params(nosuch__k=3)
    with pytest.raises(EstimatorInputError, match="unknown parameter 'matchr'"):
        clf.set_params(matchr="dtw")
    with pytest.raises(EstimatorInputError, match="out of range"):
        clf.set_params(matcher__candidates=-1)
    with pytest.raises(EstimatorInputError, match="has no capture group"):
        load_recordings(dest / "repertoire", profile, group="max")
    streams, truth = load_streams(dest / "streams", profile)
    with pytest.raises(EstimatorInputError, match="2 streams and 1 segment lists"):
        MovementSegmenter(profile).fit(streams).score(streams, truth[:1])
    from sklearn.exceptions import NotFittedError

    with pytest.raises(NotFittedError):
        MovementClassifier(profile).predict(X)


def test_a_parameters_own_table_is_set_key_by_key(data):
    """A parameter's own table (body-mapping's ``dwell``) is reached as ``TABLE__NAME__KEY``: each key alone, the
    others left at what they were; the table itself is not a parameter of its own."""
    _, profile = data
    clf = MovementClassifier(profile, correspondence="body-mapping").set_params(correspondence__dwell__speed=0.2)
    params = clf.get_params()
    assert params["correspondence__dwell__speed"] == 0.2 and params["correspondence__dwell__window"] == 0.5
    assert "correspondence__dwell" not in params
    assert clf.settings == {"correspondence": {"dwell": {"speed": 0.2}}}
    assert clone(clf).get_params() == params
    with pytest.raises(EstimatorInputError, match="correspondence__dwell__sped"):
        clf.set_params(correspondence__dwell__sped=1.0)


# -- estimators a notebook user can keep (issue 37) -----------------------------------------------------------


@pytest.fixture(scope="module")
def fitted(data):
    dest, profile = data
    X, y, _ = load_recordings(dest / "repertoire", profile)
    Xd, yd, _ = load_recordings(dest / "demos", profile)
    return MovementClassifier(profile).fit(X, y), Xd[::4]


def _same_answers(a, b, X):
    assert list(a.predict(X)) == list(b.predict(X))
    np.testing.assert_array_equal(a.decision_function(X), b.decision_function(X))
    assert [o.decided_at for o in a.observe(X)] == [o.decided_at for o in b.observe(X)]


@pytest.mark.parametrize("how", ["pickle", "joblib", "deepcopy"])
def test_a_fitted_classifier_round_trips(fitted, tmp_path, how):
    clf, X = fitted
    if how == "pickle":
        again = pickle.loads(pickle.dumps(clf))
    elif how == "joblib":
        joblib.dump(clf, tmp_path / "clf.joblib")
        again = joblib.load(tmp_path / "clf.joblib")
    else:
        again = copy.deepcopy(clf)
    assert again is not clf and again.character_ is not clf.character_
    assert hasattr(clf, "character_"), "pickling must leave the original fitted"
    assert again.get_params() == clf.get_params()
    assert list(again.classes_) == list(clf.classes_)
    _same_answers(clf, again, X)


def test_a_fitted_classifier_with_its_own_plugin_parameters_round_trips(data):
    dest, profile = data
    X, y, _ = load_recordings(dest / "repertoire", profile)
    Xd, _, _ = load_recordings(dest / "demos", profile)
    clf = MovementClassifier(profile, matcher="dtw").set_params(matcher__window=0.3).fit(X, y)
    again = pickle.loads(pickle.dumps(clf))
    assert again.character_.matcher.name == "dtw" and again.get_params()["matcher__window"] == 0.3
    _same_answers(clf, again, Xd[::5])


def test_what_the_fitted_observer_learned_is_pickled(fitted):
    """A movement the observer learned after fit (its posegraph's learned state) comes back with it; the
    original is not changed by pickling it."""
    clf, X = fitted
    learner = copy.deepcopy(clf)
    motor = learner.character_.motor
    take = X[0].positions[:: max(1, X[0].n_frames // 6)] - X[0].positions[:1, :1]
    motor.learn("windmill", take, announce=False)
    again = pickle.loads(pickle.dumps(learner))
    assert "windmill" in again.character_.motor.movements()
    assert again.character_.motor.get_state() == motor.get_state()
    assert "windmill" not in clf.character_.motor.movements()


def test_a_fitted_segmenter_round_trips(data):
    dest, profile = data
    streams, _ = load_streams(dest / "streams", profile)
    seg = MovementSegmenter(profile).fit(streams)
    for again in (pickle.loads(pickle.dumps(seg)), copy.deepcopy(seg)):
        assert again.predict(streams) == seg.predict(streams)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(PARAM_SETS)
def test_unfitted_estimators_round_trip_with_their_params(data, params):
    _, profile = data
    clf = MovementClassifier(profile).set_params(**params)
    again = pickle.loads(pickle.dumps(clf))
    assert again.get_params() == clf.get_params()
    assert not hasattr(again, "character_")
    with pytest.raises(NotFittedError):
        again.predict([np.zeros((3, len(profile.body.parts), 3))])


def test_tags_say_what_the_input_is(data):
    """Lists of (frames, parts, 3) arrays with NaN where a part is not seen; not a 2-D feature matrix."""
    _, profile = data
    for est, kind in ((MovementClassifier(profile), "classifier"), (MovementSegmenter(profile), None)):
        tags = est.__sklearn_tags__()
        assert tags.input_tags.three_d_array and tags.input_tags.allow_nan
        assert not tags.input_tags.two_d_array and not tags.input_tags.sparse
        assert tags.requires_fit and tags.estimator_type == kind
    assert MovementClassifier(profile).__sklearn_tags__().target_tags.required
    assert not MovementSegmenter(profile).__sklearn_tags__().target_tags.required


@pytest.mark.parametrize("check", [
    "check_no_attributes_set_in_init", "check_get_params_invariance", "check_set_params",
    "check_parameters_default_constructible", "check_estimator_cloneable", "check_estimator_repr",
    "check_estimator_tags_renamed", "check_valid_tag_types", "check_estimator_sparse_tag",
    "check_do_not_raise_errors_in_init_or_set_params", "check_mixin_order"])
def test_scikit_learns_api_checks_that_need_no_2d_data(data, check):
    """check_estimator itself runs nothing more on an estimator whose tags say it takes no 2-D arrays; these
    checks of the API need none (or, the sparse one, check that sparse input is refused by name)."""
    _, profile = data
    run = getattr(estimator_checks, check)
    run("MovementClassifier", MovementClassifier(profile))
    run("MovementSegmenter", MovementSegmenter(profile))


def test_nan_is_a_part_not_seen(fitted, data):
    """NaN and infinity in X are parts not seen: accepted, and a motion whose hands are hidden in a few frames is
    still recognised."""
    clf, X = fitted
    _, profile = data
    parts = list(profile.body.parts)
    arrays = [m.positions.copy() for m in X]
    for a in arrays:
        a[1:4, parts.index("left_hand")] = np.nan
        a[5, parts.index("right_hand")] = np.inf
    assert list(MovementClassifier(profile, fps=X[0].fps).fit(X, clf.predict(X)).predict(arrays)) == \
        list(clf.predict(X))


def test_complex_sparse_and_odd_input_is_refused_by_name(fitted, data):
    clf, X = fitted
    _, profile = data
    y = list(clf.predict(X))
    with pytest.raises(EstimatorInputError, match=r"X\[0\] holds complex numbers") as err:
        MovementClassifier(profile).fit([X[0].positions.astype(complex)] + X[1:], y)
    assert err.value.key == ("X", 0) and "real numbers" in str(err.value)
    with pytest.raises(ValueError, match=r"X\[1\] holds strings"):
        clf.predict([X[0].positions, np.full((3, len(profile.body.parts), 3), "a")])
    with pytest.raises(EstimatorInputError, match=r"X\[0\] holds objects"):
        clf.predict([np.array([[[None] * 3] * len(profile.body.parts)])])
    with pytest.raises(EstimatorInputError, match=r"X\[0\] is a ragged sequence"):
        clf.predict([[[[0.0, 0.0, 0.0]], [[0.0, 0.0]]]])
    with pytest.raises(EstimatorInputError, match="sparse input is not supported"):
        clf.predict(sparse.csr_matrix(np.eye(3)))


@pytest.mark.parametrize("y, message", [
    (lambda n: np.linspace(0.0, 1.0, n), "y is continuous"),
    (lambda n: np.arange(n) + 0.5, "y is continuous"),
    (lambda n: np.arange(n) * (1 + 1j), "y is not labels"),
    (lambda n: [np.nan] + [1.0] * (n - 1), "y is not labels"),
    (lambda n: np.array(["bow"] + [1] * (n - 1), dtype=object), "mixes labels of several types"),
])
def test_targets_that_are_not_classes_are_refused(fitted, data, y, message):
    clf, X = fitted
    _, profile = data
    with pytest.raises(EstimatorInputError, match=message) as err:
        MovementClassifier(profile).fit(X, y(len(X)))
    assert err.value.key == ("y",)
    assert "movement labels" in str(err.value) or "one type" in str(err.value)


def test_whole_floats_are_classes(fitted, data):
    """Labels 0.0, 1.0, ... are classes (scikit-learn's multiclass), as integers are."""
    clf, X = fitted
    _, profile = data
    names = sorted(set(clf.predict(X)))
    y = np.array([float(names.index(label)) for label in clf.predict(X)])
    assert MovementClassifier(profile, unknown=-1.0).fit(X, y).score(X, y) == 1.0


def test_grid_search_over_a_list_of_grids_mixing_matchers_and_their_parameters(performers, data):
    """A list of grids, as scikit-learn takes it: dtw alone, path-search with its own beam width; the base's
    path-search parameters do not follow the candidate that puts dtw in the matcher's table."""
    _, profile = data
    X, y, groups = performers
    base = MovementClassifier(profile).set_params(matcher__beam__k=5)
    grid = [{"matcher": ["dtw"]}, {"matcher": ["path-search"], "matcher__beam__k": [1, 8]}]
    search = GridSearchCV(base, grid, cv=LeaveOneGroupOut(), error_score="raise").fit(X, y, groups=groups)
    assert search.cv_results_["params"] == [{"matcher": "dtw"}, {"matcher": "path-search", "matcher__beam__k": 1},
                                            {"matcher": "path-search", "matcher__beam__k": 8}]
    for params, score in zip(search.cv_results_["params"], search.cv_results_["mean_test_score"]):
        alone = cross_val_score(clone(base).set_params(**params), X, y, groups=groups, cv=LeaveOneGroupOut())
        assert score == pytest.approx(alone.mean())
    assert min(search.cv_results_["mean_test_score"]) > 0.5
    assert search.best_estimator_.character_.matcher.name == search.best_params_["matcher"]


def test_another_plugin_drops_the_old_ones_parameters(data):
    _, profile = data
    clf = MovementClassifier(profile).set_params(matcher__beam__k=5, segmenter__threshold=0.1)
    clf.set_params(matcher="dtw")
    assert clf.settings == {"segmenter": {"threshold": 0.1}}
    assert "matcher__beam__k" not in clf.get_params() and "matcher__window" in clf.get_params()
    same = MovementClassifier(profile).set_params(matcher__beam__k=5)
    same.set_params(matcher="path-search")  # the same plugin: its parameters stay
    assert same.get_params()["matcher__beam__k"] == 5
    given = MovementClassifier(profile).set_params(matcher="dtw", settings={"matcher": {"window": 0.2}})
    assert given.get_params()["matcher__window"] == 0.2  # settings given with it are kept as given
    with pytest.raises(EstimatorInputError, match="unknown parameter 'matcher__beam__k' of matcher plugin 'dtw'"):
        MovementClassifier(profile).set_params(matcher="dtw", matcher__beam__k=3)
