"""Declared component parameters: defaults, types, ranges, unknown keys."""

from __future__ import annotations

import pytest

from toolkit import ConfigError, Parameter
from toolkit.params import validate_params

PARAMS = (
    Parameter("threshold", float, 0.1, "how far from the hub", minimum=0.0),
    Parameter("k", int, 5, "beam width", minimum=1, maximum=100),
    Parameter("mode", str, "mean", "how to pool", choices=("mean", "max")),
    Parameter("names", list, [], "a list", items=str),
    Parameter("table", dict, doc="required table"),
    Parameter("flag", bool, False, "a switch"),
    Parameter("even", int, 2, "an even number", check=lambda v: None if v % 2 == 0 else "must be even"),
)


def test_defaults_are_filled_and_ints_widen_to_float():
    out = validate_params("segmenter 'x'", PARAMS, {"table": {}, "threshold": 1})
    assert out == {"threshold": 1.0, "k": 5, "mode": "mean", "names": [], "table": {}, "flag": False, "even": 2}
    assert isinstance(out["threshold"], float)


@pytest.mark.parametrize(
    "values, message",
    [
        ({}, r"key table: missing required parameter of segmenter 'x'; expected a table"),
        ({"table": {}, "treshold": 1}, r"key treshold: unknown parameter 'treshold' for segmenter 'x'.*available: even, flag, k, mode, names, table, threshold"),
        ({"table": {}, "threshold": "high"}, r"key threshold: wrong type str \(value 'high'\); expected a number in \[0, inf\]"),
        ({"table": {}, "threshold": -1.0}, r"key threshold: value -1.0 out of range; expected a number in \[0, inf\]"),
        ({"table": {}, "k": 2.5}, r"key k: wrong type float"),
        ({"table": {}, "k": True}, r"key k: wrong type bool"),
        ({"table": {}, "k": 101}, r"key k: value 101 out of range"),
        ({"table": {}, "mode": "median"}, r"key mode: value 'median' not allowed.*available: mean, max"),
        ({"table": {}, "names": ["a", 3]}, r"key names\[1\]: wrong type int"),
        ({"table": {}, "flag": 1}, r"key flag: wrong type int"),
        ({"table": {}, "even": 3}, r"key even: must be even"),
        ({"table": []}, r"key table: wrong type list"),
    ],
)
def test_bad_values_name_key_expected_and_available(values, message):
    with pytest.raises(ConfigError, match=message):
        validate_params("segmenter 'x'", PARAMS, values)


def test_describe_is_readable():
    assert PARAMS[1].describe() == "integer in [1, 100], default 5"
    assert PARAMS[4].describe() == "table, required"
    assert PARAMS[3].describe() == "array of strings, default []"


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_numbers_are_refused_with_the_key(value):
    from toolkit.params import parse_settings

    settings = parse_settings([f"matcher.k={value}", f"segmenter.floor={value}"])
    with pytest.raises(ConfigError, match=rf"key floor: value -?{value.lstrip('-')} is not a finite number"):
        validate_params("segmenter 'x'", [Parameter("floor", float, 0.0, minimum=0.0)], settings["segmenter"])


def test_a_setting_nested_too_deep_is_refused():
    from toolkit.params import parse_settings

    value = parse_settings(["keys=" + "[" * 31 + "]" * 31], tables=False)["keys"]  # with its table: 32 levels
    depth = 0
    while isinstance(value, list):
        depth, value = depth + 1, value[0] if value else None
    assert depth == 31
    for depth in (33, 5000):
        with pytest.raises(ConfigError, match="key --set: value of 'keys' nested more than 32 levels deep"):
            parse_settings([f"keys={'[' * depth}{']' * depth}"], tables=False)
