"""Declared component parameters: defaults, types, ranges, unknown keys."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

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
        ({"table": {}, "threshold": "high"}, r"key threshold: wrong type str \(value 'high'\); expected a number in \[0, 1e\+09\]"),
        ({"table": {}, "threshold": -1.0}, r"key threshold: value -1.0 out of range; expected a number in \[0, 1e\+09\]"),
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
    from toolkit.config.settings import parse_settings

    settings = parse_settings([f"matcher.k={value}", f"segmenter.floor={value}"])
    with pytest.raises(ConfigError, match=rf"key floor: value -?{value.lstrip('-')} is not a finite number"):
        validate_params("segmenter 'x'", [Parameter("floor", float, 0.0, minimum=0.0)], settings["segmenter"])


def test_a_setting_nested_too_deep_is_refused():
    from toolkit.config.settings import parse_settings

    value = parse_settings(["keys=" + "[" * 31 + "]" * 31], tables=False)["keys"]  # with its table: 32 levels
    depth = 0
    while isinstance(value, list):
        depth, value = depth + 1, value[0] if value else None
    assert depth == 31
    for depth in (33, 5000):
        with pytest.raises(ConfigError, match="key --set: value of 'keys' nested more than 32 levels deep"):
            parse_settings([f"keys={'[' * depth}{']' * depth}"], tables=False)


# -- a parameter's own table: options that only mean something together --------------------------------------------

DWELL = (
    Parameter("rest", str, "dwell", "how the rest is found", choices=("dwell", "none")),
    Parameter("dwell", doc="with rest = dwell", parameters=(
        Parameter("speed", float, 0.05, "slow enough", minimum=0.0, length=True),
        Parameter("window", float, 0.5, "smoothing", minimum=0.0),
    )),
)


def test_a_table_comes_back_whole_with_its_defaults():
    assert DWELL[1].table and DWELL[1].type is dict and DWELL[1].default == {"speed": 0.05, "window": 0.5}
    assert validate_params("correspondence 'c'", DWELL, {}) == {"rest": "dwell", "dwell": {"speed": 0.05, "window": 0.5}}
    out = validate_params("correspondence 'c'", DWELL, {"dwell": {"window": 2}})
    assert out["dwell"] == {"speed": 0.05, "window": 2.0} and isinstance(out["dwell"]["window"], float)
    assert DWELL[1].describe() == "table of speed, window"


@pytest.mark.parametrize("values, message", [
    ({"dwell": {"sped": 1.0}}, r"key dwell.sped: unknown parameter 'sped' in table 'dwell' of correspondence 'c'; "
                               r"expected a parameter of table 'dwell' of correspondence 'c'; available: speed, window"),
    ({"dwell": {"speed": -1.0}}, r"key dwell.speed: value -1.0 out of range; expected a number in \[0, 1e\+09\]"),
    ({"dwell": 0.05}, r"key dwell: wrong type float \(value 0.05\); expected a table of speed, window"),
])
def test_a_bad_key_of_a_table_is_named_with_its_path(values, message):
    with pytest.raises(ConfigError, match=message):
        validate_params("correspondence 'c'", DWELL, values)


def test_lengths_inside_a_table_are_scaled_with_the_body():
    from toolkit.params import length_names, scaled

    assert length_names(DWELL) == [("dwell", "speed")]
    values = validate_params("correspondence 'c'", DWELL, {})
    assert scaled(values, length_names(DWELL), 2.0) == {"rest": "dwell", "dwell": {"speed": 0.1, "window": 0.5}}
    assert values["dwell"]["speed"] == 0.05  # the values as declared are left alone


def test_set_reaches_inside_a_table_and_is_checked_there(pm):
    from toolkit.config.settings import check_settings, parse_settings

    settings = parse_settings(["correspondence.dwell.speed=0.2", "correspondence.dwell.window=1", "correspondence.rest=none"])
    assert settings == {"correspondence": {"dwell": {"speed": 0.2, "window": 1}, "rest": "none"}}
    plugins = {"correspondence": ["body-mapping"]}
    check_settings(settings, pm, plugins)
    with pytest.raises(ConfigError, match=r"key --set.correspondence.dwell.sped: unknown parameter 'sped' in table "
                                          r"'dwell' of correspondence 'body-mapping'.*available: memory, speed, window"):
        check_settings(parse_settings(["correspondence.dwell.sped=0.2"]), pm, plugins)
    with pytest.raises(ConfigError, match=r"given both a value and keys"):
        parse_settings(["correspondence.dwell=1", "correspondence.dwell.speed=0.2"])


def test_a_set_inside_a_table_keeps_the_templates_other_keys(pm, write):
    """``--set TABLE.KEY.INNER`` merges into the template's table key by key (the observer composed keeps the
    template's other inner keys)."""
    from toolkit.observe import observer_tables

    template = write("t.toml", """
        [observer]
        name = "t"
        [motor]
        plugin = "posegraph"
        [correspondence]
        plugin = "body-mapping"
        [correspondence.dwell]
        window = 2.0
        memory = 10.0
        """)
    tables = observer_tables(pm, settings={"correspondence": {"dwell": {"memory": 5.0}}}, template=template)[1]
    assert tables["correspondence"]["dwell"] == {"window": 2.0, "memory": 5.0}


def test_a_duration_is_bounded_by_an_hour_unless_it_says_otherwise():
    from toolkit.params import MAX_SECONDS

    assert Parameter("t", float, 1.0, seconds=True).maximum == MAX_SECONDS == 3600.0
    assert Parameter("t", float, 1.0, seconds=True, maximum=5.0).maximum == 5.0
    assert Parameter("t", float, 1.0, seconds=True).coerce(3600) == 3600.0
    with pytest.raises(ConfigError, match=r"value 1e\+308 out of range.*expected a number in \[-1e\+09, 3600\]"):
        Parameter("t", float, 1.0, seconds=True).coerce(1e308)


@given(st.floats(min_value=1e9, max_value=1.7e308, exclude_min=True))
def test_a_number_without_a_maximum_is_at_most_a_billion(value):
    from toolkit.params import MAX_MAGNITUDE

    p = Parameter("x", float, 1.0, minimum=0.0)
    assert p.coerce(MAX_MAGNITUDE) == MAX_MAGNITUDE
    for v in (value, -value):
        with pytest.raises(ConfigError) as err:
            Parameter("x", float, 1.0).coerce(v)
        assert err.value.key == ("x",) and "too large" in str(err.value) and "[-1e+09, 1e+09]" in str(err.value)
    with pytest.raises(ConfigError, match=r"\[0, 1e\+09\]"):
        p.coerce(value)


def test_every_range_listed_is_the_range_the_check_holds():
    """``likeme plugins --params`` (and docs/components.md) show each number parameter's range from
    :attr:`Parameter.bounds`, the range :meth:`Parameter.coerce` holds it to: for every registered component, both
    ends are listed, both are taken, and the next number past either end is refused naming the key."""
    import math

    from likeme.cli.plugins import plugins_table
    from toolkit import create_plugin_manager
    from toolkit.components import KINDS
    from toolkit.params import flat_parameters

    pm = create_plugin_manager(autoload=False)
    listed = {}

    def collect(rows, prefix):
        for row in rows:
            listed[(*prefix, row["name"])] = row["type"]
            collect(row.get("parameters", []), (*prefix, row["name"]))

    for kind, rows in plugins_table(pm, params=True)["components"].items():
        for row in rows:
            collect(row["parameters"], (kind, row["name"]))
    checked = 0
    for kind in KINDS:
        for info in pm.registry.infos(kind):
            for key, p in flat_parameters(info.cls.parameters):
                if p.type not in (int, float) or p.choices is not None:
                    continue
                lo, hi = p.bounds
                shown = listed[(kind, info.name, *key)]
                assert "inf" not in shown and f"in [{lo if p.type is int else format(lo, 'g')}, " in shown, shown
                assert f", {hi if p.type is int else format(hi, 'g')}]" in shown, shown
                past = (lo - 1, hi + 1) if p.type is int else (math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf))
                for value in past:
                    with pytest.raises(ConfigError) as err:
                        p.coerce(value)
                    assert err.value.key == (p.name,)
                if p.check is None:
                    assert p.coerce(lo) == lo and p.coerce(hi) == hi
                checked += 1
    assert checked > 100
