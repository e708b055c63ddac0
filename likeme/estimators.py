"""Estimators in the scikit-learn style over the toolkit's plugins, for a notebook (``docs/python-api.md``).

Thin classes with no algorithm of their own: each composes an observer (:func:`toolkit.observe.compose_observer`)
from a body profile, an observer template and plugin names, with its repertoire built in memory from the motions
it is fitted on (:func:`plugins.lib.clip_repertoire.clip_repertoire`), and watches motions with
:class:`toolkit.observe.Observer`, as ``likeme bench recognition|segmentation`` do with folders of files:

- :class:`MovementClassifier`: ``fit(motions, labels)`` makes the labelled motions the observer's repertoire;
  ``predict`` recognises each motion as one segment (``"unknown"`` when the matcher rejects it).
- :class:`MovementSegmenter`: ``fit(streams)`` finds the hubs (the poses movements start and end in) from the
  streams or from a repertoire given; ``predict`` cuts each stream into end-exclusive movement segments.

Both are scikit-learn estimators (:class:`sklearn.base.BaseEstimator`): ``get_params``/``set_params`` cover the
constructor's arguments and, as ``TABLE__KEY``, every parameter of the plugin each component table has
(``matcher__k``, ``segmenter__threshold``, ``motor__hub_radius``), checked against the plugin's parameters, so
:func:`sklearn.base.clone`, :func:`sklearn.model_selection.cross_val_score` and
:class:`~sklearn.model_selection.GridSearchCV` work over them.

A fitted estimator pickles (``pickle``, ``joblib``, ``copy.deepcopy``): its repertoire and its observer's learned
state are kept, and the observer is composed again when it is loaded. A list of grids may name components and
their own parameters together: naming another plugin for a table drops the old plugin's parameters.

``X`` is a sequence of :class:`~toolkit.motion.Motion` (world positions of the profile's parts, metres, +y up, as
:meth:`BodyProfile.read` gives them) or of arrays shaped (frames, parts, 3) in the profile's part order (NaN where a
part is not seen) at the estimator's ``fps``; complex, string or object arrays, sparse matrices and a continuous
``y`` are refused by name. :func:`load_recordings` and :func:`load_streams` read folders.
"""

from __future__ import annotations

import copy
import functools
import re
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy import sparse
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.multiclass import type_of_target
from sklearn.utils.validation import check_is_fitted

from plugins.bench.metrics import segmentation_scores
from plugins.lib.clip_repertoire import ClipRepertoire, clip_files, clip_repertoire
from toolkit.errors import ConfigError
from toolkit.motion import Motion
from toolkit.config.observer_templates import OBSERVER_TEMPLATE
from toolkit.observe import Observation, Observer, compose_observer, observer_tables
from toolkit.params import flat_parameters
from toolkit.recordings import is_recording
from toolkit.recordings.profile import BodyProfile, load_profile
from toolkit.recordings.segments import read_segments, segments_of
from toolkit.state import apply_state, character_state

__all__ = ["MovementClassifier", "MovementSegmenter", "EstimatorInputError", "load_recordings", "load_streams",
           "to_breakpoints", "UNKNOWN"]

UNKNOWN = "unknown"
"""What :meth:`MovementClassifier.predict` answers for a motion the matcher rejects (none of the repertoire's
movements), as ``likeme bench recognition`` counts it; never a movement label."""

HIDDEN = {("motor", "clips"), ("motor", "profile")}
"""Plugin parameters the estimators set themselves (the repertoire is given in memory), not offered as params."""


class EstimatorInputError(ConfigError, ValueError):
    """Bad input to an estimator (``X``, ``y`` or a parameter): a :class:`ConfigError` that scikit-learn, which
    expects a :class:`ValueError`, recognises too."""


@functools.cache
def _plugin_manager() -> Any:
    from toolkit.manager import create_plugin_manager

    return create_plugin_manager()


class _ObserverEstimator(BaseEstimator):
    """What both estimators share: the observer's arguments, the plugin parameters as params, the input checks,
    the tags and the pickled state."""

    _composed: dict[str, Any] = {}  # extra compose_observer arguments of the kind (segmenter-only: matcher=None)
    _components = ("matcher", "segmenter", "motor", "correspondence")  # arguments naming a table's plugin

    # -- what scikit-learn may assume ----------------------------------------------------------------

    def __sklearn_tags__(self) -> Any:
        """``X`` is a sequence of motions, each (frames, parts, 3) with NaN where a part is not seen; not a 2-D
        array of features. Sparse, categorical, string or dict input is not accepted."""
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.input_tags.allow_nan = True
        tags.requires_fit = True
        return tags

    # -- pickling (pickle, joblib, copy.deepcopy) ------------------------------------------------------

    def __getstate__(self) -> dict[str, Any]:
        """The estimator's state without the composed observer (it holds the plugin manager, which cannot be
        pickled): its learned state (:func:`toolkit.state.character_state`) is kept instead, and
        :meth:`__setstate__` composes the observer again from the same arguments and repertoire."""
        state = dict(super().__getstate__())  # object.__getstate__ gives the instance's own __dict__
        character = state.pop("character_", None)
        if character is not None:
            state["_learned_"] = {"actors": {"observer": character_state(character)}}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        learned = state.pop("_learned_", None)
        super().__setstate__(state)
        if learned is not None:
            character = self._compose(self.repertoire_)
            apply_state(character, learned, f"<pickled {type(self).__name__}>")
            self.character_ = character

    # -- the observer ------------------------------------------------------------------------------

    def _profile(self) -> BodyProfile:
        if isinstance(self.profile, BodyProfile):
            return self.profile
        if isinstance(self.profile, (str, Path)):
            return load_profile(self.profile)
        raise EstimatorInputError(f"a profile of type {type(self.profile).__name__}", key=("profile",),
                                  expected="a BodyProfile or the path of a body profile TOML file")

    def _observer_args(self) -> dict[str, Any]:
        args = {"segmenter": self.segmenter, "matcher": getattr(self, "matcher", None), "motor": self.motor,
                "correspondence": self.correspondence, "template": self.template, "settings": self.settings}
        return {**args, **self._composed}

    def _tables(self) -> dict[str, dict[str, Any]]:
        """The component tables the observer will have: plugin and parameters given, per table."""
        return observer_tables(_plugin_manager(), **self._observer_args())[1]

    def _plugins(self) -> dict[str, str | None]:
        """The plugin of each component table the observer will have (the arguments' or the template's)."""
        return {table: values.get("plugin") for table, values in self._tables().items()}

    def _plugin_parameters(self) -> dict[str, dict[str, Any]]:
        """Every parameter (:class:`toolkit.params.Parameter`) of each table's plugin, by table and name; the
        parameters of a parameter's own table by ``NAME__KEY`` (not the table itself)."""
        registry = _plugin_manager().registry
        return {table: {"__".join(path): p for path, p in flat_parameters(registry.get(table, values["plugin"]).parameters)
                        if not p.table and (table, path[0]) not in HIDDEN}
                for table, values in self._tables().items()}

    def _compose(self, repertoire: Any) -> Any:
        args = self._observer_args()
        return compose_observer(_plugin_manager(), self._profile(), repertoire,
                                lengths_for_height=self.lengths_for_height, **args)

    def _repertoire(self, motions: Sequence[Motion], labels: Sequence[str]) -> Any:
        """The clips as a repertoire in memory, its hubs found with the motor system's settings."""
        motor = self._tables().get("motor", {})
        defaults = {name: p.default for name, p in self._plugin_parameters().get("motor", {}).items()}
        radius = motor.get("hub_radius", defaults.get("hub_radius", 0.06))
        share = motor.get("hub_share", defaults.get("hub_share", 0.2))
        return clip_repertoire(motions, labels, self._profile(), hub_radius=radius, hub_share=share)

    # -- scikit-learn parameters -------------------------------------------------------------------

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The constructor's arguments; with ``deep``, also ``TABLE__KEY`` for every parameter of each component
        table's plugin (its value as written for the observer: given, the template's, or the default; a length
        parameter is scaled to the body's height when composed, as ``lengths_for_height`` says)."""
        params = super().get_params(deep=False)
        if deep:
            available = self._plugin_parameters()
            for table, values in self._tables().items():
                for name, p in available[table].items():
                    given = _get(values, name.split("__"))
                    if not p.required or given is not _MISSING:
                        params[f"{table}__{name}"] = p.default if given is _MISSING else given
        return params

    def set_params(self, **params: Any) -> _ObserverEstimator:
        """Set constructor arguments (``matcher="dtw"``) and plugin parameters (``matcher__k=4``); a plugin
        parameter is checked against the parameters of the plugin its table has (after the arguments given
        here), an unknown one is an :class:`EstimatorInputError` listing the available ones.

        An argument that puts another plugin in a table (``matcher="dtw"`` after ``path-search``) drops the
        parameters set for the old plugin, as replacing a pipeline's step drops the old step's parameters: a list
        of grids ``[{"matcher": ["dtw"]}, {"matcher": ["path-search"], "matcher__beam__k": [2, 8]}]`` runs from
        any base estimator. Naming a plugin and a parameter it lacks in one call is still an error."""
        names = self._get_param_names()
        nested = {k: v for k, v in params.items() if "__" in k}
        for key, value in params.items():
            if "__" in key:
                continue
            if key not in names:
                raise EstimatorInputError(f"unknown parameter {key!r} of {type(self).__name__}", key=(key,),
                                          expected="an argument or a TABLE__KEY plugin parameter",
                                          available=names)
        swapped = "settings" not in params and any(k in (*self._components, "template") for k in params)
        before = self._plugins() if swapped else {}
        for key, value in params.items():
            if "__" not in key:
                setattr(self, key, value)
        if before and self.settings:
            # another plugin in a table: the old one's parameters go with it (as a pipeline step's do when the
            # step is replaced), so that a grid may name a component and its own parameters together
            after = self._plugins()
            changed = {t for t in self.settings if before.get(t) != after.get(t)}
            if changed:
                self.settings = {t: v for t, v in self.settings.items() if t not in changed}
        if nested:
            available = self._plugin_parameters()
            settings = copy.deepcopy({k: dict(v) for k, v in (self.settings or {}).items()})
            for name, value in nested.items():
                table, key = name.split("__", 1)
                if key not in available.get(table, {}):
                    raise EstimatorInputError(
                        f"unknown parameter {name!r}" + (f" of {table} plugin {self._tables()[table]['plugin']!r}"
                                                          if table in available else ""),
                        key=(name,), expected="a parameter of the plugin of one of the observer's tables",
                        available=[f"{t}__{k}" for t in available for k in available[t]])
                try:
                    value = available[table][key].coerce(value)
                except ConfigError as err:
                    raise EstimatorInputError(err.problem, key=(name,), expected=err.expected,
                                              available=err.available) from None
                *inner, last = key.split("__")
                where = settings.setdefault(table, {})
                for part in inner:  # a key of a parameter's own table
                    where = where.setdefault(part, {})
                where[last] = value
            self.settings = settings
        return self

    # -- input -------------------------------------------------------------------------------------

    def _motions(self, X: Any, what: str = "X") -> list[Motion]:
        """``X`` as motions in the profile's parts, each checked."""
        parts = tuple(self._profile().body.parts)
        if sparse.issparse(X):
            raise EstimatorInputError(f"{what} is a sparse matrix: sparse input is not supported", key=(what,),
                                      expected="a sequence of motions, each an array (frames, parts, 3)")
        if isinstance(X, (Motion, str, bytes)) or (isinstance(X, np.ndarray) and X.ndim == 3):
            raise EstimatorInputError(f"{what} is one {'motion' if not isinstance(X, (str, bytes)) else 'string'}",
                                      key=(what,), expected="a sequence of motions (a list, or an array "
                                      "(motions, frames, parts, 3))")
        try:
            items = list(X)
        except TypeError:
            raise EstimatorInputError(f"{what} of type {type(X).__name__}", key=(what,),
                                      expected="a sequence of motions") from None
        if not items:
            raise EstimatorInputError(f"{what} is empty", key=(what,), expected="at least one motion")
        out = []
        for i, item in enumerate(items):
            if isinstance(item, Motion):
                _real_array(item.positions, what, i)
                missing = [p for p in parts if p not in item.parts]
                if missing:
                    raise EstimatorInputError(f"{what}[{i}] lacks parts {missing}", key=(what, i),
                                              expected=f"a motion of the profile's parts {list(parts)}",
                                              available=list(item.parts))
                out.append(item if item.parts == parts else item.select(parts))
                continue
            array = _real_array(item, what, i)
            if array.ndim != 3 or array.shape[1:] != (len(parts), 3):
                raise EstimatorInputError(f"{what}[{i}] has shape {array.shape}", key=(what, i),
                                          expected=f"(frames, {len(parts)}, 3): the profile's parts {list(parts)}")
            out.append(Motion(array, self.fps, parts))
        return out


class MovementClassifier(ClassifierMixin, _ObserverEstimator):
    """Recognises whole motions as movements of a repertoire built from the labelled motions it is fitted on.

    ``fit(X, y)`` makes each motion of ``X`` a clip of movement ``y`` of the observer's repertoire (hubs found
    from them: :mod:`plugins.lib.clip_repertoire`); ``predict(X)`` classifies each motion as one segment, as
    ``likeme bench recognition`` classifies a demo clip (:meth:`toolkit.observe.Observer.classify`).

    Parameters
    ----------
    profile : BodyProfile or path
        The body profile the motions are in (its parts, root, facing).
    matcher : str
        The matcher plugin (``path-search``, ``forward-model``, ``dtw``...); the template's own keeps its
        parameters.
    motor, segmenter, correspondence, lengths_for_height, template
        As :func:`toolkit.observe.compose_observer` (``None``/``""``: the template's).
    settings : mapping, optional
        Plugin parameters per table, ``{"matcher": {"k": 4}}``; ``set_params(matcher__k=4)`` writes here.
    fps : float
        The frame rate of motions given as arrays.
    unknown : object
        What :meth:`predict` answers for a motion the matcher rejects (:data:`UNKNOWN`); with labels that are not
        strings, give one of their kind (``-1``) so that answers and labels compare.

    Attributes
    ----------
    classes_ : ndarray
        The movement labels fitted, sorted (``"unknown"`` is never one); labels that are not strings (numbers)
        name the movements by their text and come back from :meth:`predict` as they were given.
    character_ : Character
        The observer composed by :meth:`fit`.
    repertoire_ : ClipRepertoire
        Its repertoire, built in memory from the motions fitted.
    """

    def __init__(self, profile: Any, matcher: str = "path-search", *, motor: str | None = None,
                 segmenter: str | None = None, correspondence: str | None = "",
                 lengths_for_height: float | None | str = "", template: str | Path = OBSERVER_TEMPLATE,
                 settings: Mapping[str, Mapping[str, Any]] | None = None, fps: float = 30.0,
                 unknown: Any = UNKNOWN) -> None:
        self.profile = profile
        self.matcher = matcher
        self.motor = motor
        self.segmenter = segmenter
        self.correspondence = correspondence
        self.lengths_for_height = lengths_for_height
        self.template = template
        self.settings = settings
        self.fps = fps
        self.unknown = unknown

    def fit(self, X: Any, y: Any) -> MovementClassifier:
        """Build the repertoire from the motions ``X`` labelled ``y`` and compose the observer."""
        motions = self._motions(X)
        labels = _labels(y, len(motions), unknown=self.unknown)
        self.repertoire_ = self._repertoire(motions, labels)
        self.character_ = self._compose(self.repertoire_)
        self.classes_ = np.unique(np.asarray(y))
        self._label_of = {str(c): c for c in self.classes_}  # a movement's name -> the label it was given as
        return self

    def observe(self, X: Any) -> list[Observation]:
        """What the observer makes of each motion: the :class:`~toolkit.watching.Observation` (its match, with the
        matcher's details, and the frame it decided at)."""
        check_is_fitted(self, "character_")
        body = self._profile().body
        return [Observer(self.character_, body, m.fps).classify(m) for m in self._motions(X)]

    def predict(self, X: Any) -> np.ndarray:
        """The label of each motion's movement, or ``unknown`` (:data:`UNKNOWN`) where the matcher rejects it."""
        return np.asarray([self._label_of[obs.movement] if obs.movement in self._label_of else self.unknown
                           for obs in self.observe(X)])

    def decision_function(self, X: Any) -> np.ndarray:
        """The matcher's confidence in [0, 1] in the movement it recognised, 0 for every other class.

        Shaped (motions, classes) in the order of :attr:`classes_` (all 0 for a motion answered "unknown");
        with two classes (motions,): the confidence, negative when the answer is ``classes_[0]``. What a
        confidence means is the matcher's: ``path-search`` exp(-mean pose distance / ``scale``) times the
        share of the path's votes for the movement; ``dtw`` 1 - distance / the runner-up's distance (the
        margin); ``forward-model`` exp(-prediction error / its limit) of the committed path. Matchers give no
        score to the movements they did not answer, so there is no ``predict_proba``.
        """
        observations = self.observe(X)
        scores = np.zeros((len(observations), len(self.classes_)))
        index = {str(c): i for i, c in enumerate(self.classes_)}
        for row, obs in enumerate(observations):
            if obs.movement in index and obs.match is not None:
                scores[row, index[obs.movement]] = obs.match.confidence
        if len(self.classes_) == 2:
            return scores[:, 1] - scores[:, 0]
        return scores


class MovementSegmenter(_ObserverEstimator):
    """Cuts streams of motion into movement segments with a segmenter plugin.

    ``fit(X)`` finds the hubs the segmenter compares with: from ``repertoire`` when one is given, else from the
    streams themselves (each a clip: its ends give the hubs), as ``likeme bench segmentation`` does without
    ``--repertoire``. ``predict(X)`` gives each stream's segments, end exclusive.

    Parameters
    ----------
    profile : BodyProfile or path
        The body profile the streams are in.
    segmenter : str
        The segmenter plugin (``hub-threshold``, ``velocity-direction``, ``ruptures``).
    repertoire : ClipRepertoire or (motions, labels), optional
        The repertoire whose hubs the segmenter uses (:func:`plugins.lib.clip_repertoire.clip_repertoire`, or the
        labelled motions to build it from).
    motor, correspondence, lengths_for_height, template, settings, fps
        As :class:`MovementClassifier` (``segmenter__threshold`` and the like are plugin parameters).

    Attributes
    ----------
    character_ : Character
        The observer composed by :meth:`fit` (no matcher).
    repertoire_ : ClipRepertoire
        The repertoire whose hubs it uses.
    """

    _composed = {"matcher": None}

    def __init__(self, profile: Any, segmenter: str = "hub-threshold", *, repertoire: Any = None,
                 motor: str | None = None, correspondence: str | None = "", lengths_for_height: float | None | str = "",
                 template: str | Path = OBSERVER_TEMPLATE, settings: Mapping[str, Mapping[str, Any]] | None = None,
                 fps: float = 30.0) -> None:
        self.profile = profile
        self.segmenter = segmenter
        self.repertoire = repertoire
        self.motor = motor
        self.correspondence = correspondence
        self.lengths_for_height = lengths_for_height
        self.template = template
        self.settings = settings
        self.fps = fps

    def fit(self, X: Any, y: Any = None) -> MovementSegmenter:
        """Compose the observer, its hubs from ``repertoire`` or from the streams ``X`` (``y`` is not used)."""
        streams = self._motions(X)
        if y is not None:
            _segments(y, streams)
        given = self.repertoire
        if given is None:
            repertoire = self._repertoire(streams, [f"stream_{i + 1}" for i in range(len(streams))])
        elif isinstance(given, ClipRepertoire):
            repertoire = given
        elif isinstance(given, tuple) and len(given) == 2:
            motions = self._motions(given[0], "repertoire")
            repertoire = self._repertoire(motions, _labels(given[1], len(motions), "repertoire labels"))
        else:
            raise EstimatorInputError(f"a repertoire of type {type(given).__name__}", key=("repertoire",),
                                      expected="a ClipRepertoire or a (motions, labels) pair")
        self.repertoire_ = repertoire
        self.character_ = self._compose(repertoire)
        return self

    def observe(self, X: Any) -> list[list[Observation]]:
        """The observations of each stream, one per segment found (:meth:`toolkit.observe.Observer.watch`)."""
        check_is_fitted(self, "character_")
        body = self._profile().body
        return [Observer(self.character_, body, m.fps).watch(m) for m in self._motions(X)]

    def predict(self, X: Any) -> list[list[tuple[int, int]]]:
        """Each stream's movement segments as (start, end) frame pairs, end exclusive, in order; the frames
        between them are rest. :func:`to_breakpoints` turns them into ruptures' breakpoints."""
        return [[(o.segment.start, o.segment.end) for o in found] for found in self.observe(X)]

    def predict_breakpoints(self, X: Any) -> list[list[int]]:
        """Each stream's breakpoints as ruptures gives them: every segment's end exclusive, ending with the
        stream's length (movement segments and the rest between them alike)."""
        motions = self._motions(X)
        return [to_breakpoints(found, m.n_frames) for found, m in zip(self.predict(motions), motions)]

    def score(self, X: Any, y: Any) -> float:
        """The segmentation F1 of ``likeme bench segmentation`` over all streams: true positives, found and true
        segments summed over the streams (:func:`plugins.bench.metrics.segmentation_scores`).

        ``y``: each stream's true segments, (start, end) or (start, end, movement) rows, end exclusive.
        """
        motions = self._motions(X)
        truth = _segments(y, motions)
        found = tp = true = 0
        for spans, true_spans in zip(self.predict(motions), truth):
            s = segmentation_scores(spans, true_spans)
            found, tp, true = found + s["found"], tp + s["true_positives"], true + s["true"]
        precision = tp / found if found else 0.0
        recall = tp / true if true else 0.0
        return 2 * precision * recall / (precision + recall) if precision + recall else 0.0


_MISSING = object()


def _get(values: Mapping[str, Any], path: Sequence[str]) -> Any:
    """The value at a key path of nested tables, or ``_MISSING``."""
    for part in path:
        if not isinstance(values, Mapping) or part not in values:
            return _MISSING
        values = values[part]
    return values


def to_breakpoints(segments: Sequence[tuple[int, int]], n_frames: int) -> list[int]:
    """End-exclusive segments of a stream of ``n_frames`` as ruptures' breakpoints: the sorted ends of every piece
    they cut the stream into, the last ``n_frames``."""
    cuts = {int(b) for start, end in segments for b in (start, end) if 0 < b < n_frames}
    return sorted(cuts) + [int(n_frames)]


def _real_array(item: Any, what: str, i: int) -> np.ndarray:
    """One motion's positions as a float array: real numbers (NaN and infinity are parts not seen), never complex
    numbers, strings or objects."""
    if sparse.issparse(item):
        raise EstimatorInputError(f"{what}[{i}] is a sparse matrix: sparse input is not supported", key=(what, i),
                                  expected="an array (frames, parts, 3) of real numbers")
    if isinstance(item, (str, bytes)):
        raise EstimatorInputError(f"{what}[{i}] is a string", key=(what, i),
                                  expected="an array (frames, parts, 3) of real numbers")
    try:
        raw = np.asarray(item)
    except ValueError:  # ragged nested lists
        raise EstimatorInputError(f"{what}[{i}] is a ragged sequence", key=(what, i),
                                  expected="an array (frames, parts, 3) of real numbers") from None
    if raw.dtype.kind not in "biuf":
        kind = {"c": "complex numbers", "U": "strings", "S": "bytes", "O": "objects", "M": "dates",
                "m": "time spans", "V": "records"}.get(raw.dtype.kind, f"dtype {raw.dtype}")
        raise EstimatorInputError(f"{what}[{i}] holds {kind}", key=(what, i),
                                  expected="an array (frames, parts, 3) of real numbers (NaN where a part is not seen)")
    return raw.astype(float, copy=False)


def _labels(y: Any, n: int, what: str = "y", *, unknown: Any = UNKNOWN) -> list[str]:
    if isinstance(y, (str, bytes)):
        raise EstimatorInputError(f"{what} is one string", key=(what,), expected="one movement label per motion")
    if np.ndim(y) == 1 and len(y) == n:
        _check_target(y, what)
    labels = [str(v) for v in np.asarray(y, dtype=object).ravel()] if np.ndim(y) <= 1 else None
    if labels is None:
        raise EstimatorInputError(f"{what} has shape {np.shape(y)}", key=(what,), expected="one label per motion")
    if len(labels) != n:
        raise EstimatorInputError(f"{n} motions and {len(labels)} labels", key=(what,),
                                  expected="one movement label per motion")
    if str(unknown) in labels or UNKNOWN in labels:
        raise EstimatorInputError(f"the label {unknown if str(unknown) in labels else UNKNOWN!r}", key=(what,),
                                  expected=f"movement labels ({unknown!r} is what predict answers for none)")
    odd = sorted({label for label in labels if "#" in label or not label.strip()})
    if odd:
        raise EstimatorInputError(f"labels {odd}", key=(what,), expected="non-empty movement labels without '#' "
                                  "(a movement's second take is named bow#2)")
    return labels


def _check_target(y: Any, what: str) -> None:
    """Labels ``y`` are classes (:func:`sklearn.utils.multiclass.type_of_target` says binary or multiclass): not
    continuous (floats that are not whole numbers), complex, NaN or infinite."""
    expected = "movement labels (strings or integers), one per motion: a classifier of movements, not a regression"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # NaN cast while sklearn looks
        try:
            kind = type_of_target(y, input_name=what)
        except ValueError as err:  # complex numbers, NaN or infinity
            raise EstimatorInputError(f"{what} is not labels ({err})", key=(what,), expected=expected) from None
        except TypeError:  # strings and numbers mixed: no order
            raise EstimatorInputError(f"{what} mixes labels of several types", key=(what,),
                                      expected="labels of one type: all strings or all integers") from None
    if kind not in ("binary", "multiclass"):
        raise EstimatorInputError(f"{what} is {kind}" if kind == "continuous" else f"{what} is of type {kind!r}",
                                  key=(what,), expected=expected)


def _segments(y: Any, streams: Sequence[Motion]) -> list[list[tuple[int, int]]]:
    rows = list(y)
    if len(rows) != len(streams):
        raise EstimatorInputError(f"{len(streams)} streams and {len(rows)} segment lists", key=("y",),
                                  expected="the true segments of each stream")
    out = []
    for i, spans in enumerate(rows):
        try:
            pairs = [(int(s[0]), int(s[1])) for s in spans]
        except (TypeError, ValueError, IndexError):
            raise EstimatorInputError(f"y[{i}] is not a list of segments", key=("y", i),
                                      expected="(start, end) or (start, end, movement) rows") from None
        if any(not 0 <= a < b for a, b in pairs):
            raise EstimatorInputError(f"y[{i}] has a segment outside 0 <= start < end", key=("y", i),
                                      expected="end-exclusive frame pairs")
        out.append(pairs)
    return out


def load_recordings(folder: str | Path, profile: str | Path | BodyProfile, *, group: str | None = None
                    ) -> tuple[list[Motion], list[str], list[str]]:
    """The labelled recordings of ``folder`` (one sub-folder per movement, as a clip repertoire) read through
    ``profile``: (motions, labels, groups).

    ``group``: a regular expression searched in each file's name whose first capture group names its group (a
    performer, a style, a session), for :class:`~sklearn.model_selection.LeaveOneGroupOut` or ``GroupKFold``;
    without one, each file's name (without its suffix) is its group.
    """
    profile = profile if isinstance(profile, BodyProfile) else load_profile(profile)
    pattern = None
    if group is not None:
        try:
            pattern = re.compile(group)
        except re.error as err:
            raise EstimatorInputError(f"not a regular expression: {err}", key=("group",),
                                      expected="a Python regular expression with one capture group") from None
        if pattern.groups < 1:
            raise EstimatorInputError(f"{group!r} has no capture group", key=("group",),
                                      expected="a regular expression whose first capture group is the group's name")
    motions, labels, groups = [], [], []
    for label, files in clip_files(Path(folder)).items():
        for path in files:
            found = pattern.search(path.name) if pattern is not None else None
            if pattern is not None and (found is None or not found.group(1)):
                raise EstimatorInputError(f"no group in {path.name!r}", file=path, key=("group",),
                                          expected=f"file names in which {group!r} finds a group")
            motions.append(profile.read(path))
            labels.append(label)
            groups.append(found.group(1) if found is not None else path.stem)
    return motions, labels, groups


def load_streams(folder: str | Path, profile: str | Path | BodyProfile) -> tuple[list[Motion], list[list[tuple]]]:
    """The streams of ``folder`` (``NAME.bvh`` with ``NAME.segments.csv`` beside it, as ``likeme bench
    segmentation`` reads them) through ``profile``: (motions, true segments as (start, end, movement) rows)."""
    profile = profile if isinstance(profile, BodyProfile) else load_profile(profile)
    files = sorted(p for p in Path(folder).iterdir() if is_recording(p))
    if not files:
        raise EstimatorInputError("no streams found", file=folder,
                                  expected="NAME.bvh files with NAME.segments.csv beside them")
    return [profile.read(p) for p in files], [read_segments(segments_of(p)) for p in files]
