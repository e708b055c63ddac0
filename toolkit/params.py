"""Declared parameters of components, and their validation.

A component class lists its parameters as a tuple of :class:`Parameter`. The
character loader checks a TOML table against that list before the component is
built: unknown keys (listing the known ones), types, ranges and choices. The
same check runs when a component is built from Python, so ``HubThreshold(threshold="x")``
fails the same way as a bad TOML value.

Options that only mean something together with another option are a *table* of their own: a :class:`Parameter`
given ``parameters`` holds them, checked key by key like the component's own (``[correspondence.dwell] speed =
0.05``, ``--set correspondence.dwell.speed=0.05``, ``params["dwell"]["speed"]``); a key it does not have is an error
listing the keys it has, and the keys not given take their defaults.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from toolkit.errors import ConfigError

__all__ = ["Parameter", "REQUIRED", "validate_params", "finite_number", "length_names", "scaled", "flat_parameters",
           "of_owner", "MAX_SECONDS", "MAX_MAGNITUDE"]

MAX_SECONDS = 3600.0
"""The longest duration a ``seconds`` parameter takes unless it declares its own maximum: an hour. Plugins turn a
duration into frames (``round(seconds * fps)``, at up to 10,000 frames per second) and size windows and buffers by it;
an hour keeps every such count an integer of at most 3.6e7, where ``1e308`` seconds gave an infinity inside the
plugin."""

MAX_MAGNITUDE = 1e9
"""The largest magnitude a number parameter without a maximum of its own takes. No setting of a toolkit of bodies in
metres, seconds and hertz means anything beyond a billion of its unit, and a bound this far below a float's range keeps
every product a plugin forms with it (by a frame rate, a body size, a count of frames) finite: ``1e308`` is refused by
key before the plugin runs instead of overflowing inside it."""


MAX_INT = 2**63 - 1
"""The largest integer a parameter takes (what numpy and the plugins can hold)."""


def _bound(value: float, kind: type) -> str:
    """A bound as ``likeme plugins --params`` and error messages show it: an integer's in full, a number's short."""
    return str(int(value)) if kind is int and float(value).is_integer() else f"{value:g}"


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()
"""Sentinel default of a parameter that must be given."""

_TYPE_NAMES = {
    bool: "a boolean",
    int: "an integer",
    float: "a number",
    str: "a string",
    list: "an array",
    dict: "a table",
}


@dataclass(frozen=True)
class Parameter:
    """One parameter of a component.

    Parameters
    ----------
    name : str
        Key in the component's TOML table.
    type : type
        One of ``bool, int, float, str, list, dict``. ``float`` accepts integers.
    default : object
        Value when the key is absent; :data:`REQUIRED` if it must be given.
    doc : str
        What the parameter does and its effect (shown by ``likeme plugins --params``).
    minimum, maximum : float, optional
        Inclusive bounds for numbers.
    choices : sequence, optional
        The allowed values.
    items : type, optional
        Element type for ``list`` parameters.
    check : callable, optional
        ``check(value) -> str | None``: a further check returning a problem or ``None``.
    seconds : bool
        A duration in seconds, which the plugin turns into frames: at most :data:`MAX_SECONDS` unless ``maximum``
        says otherwise (Kopp & Graeser 2006, §4.1's sensory memory and Buchsbaum & Blumberg 2005, §5.1's filter are
        such durations).
    length : bool
        A length on the observer's own body (metres, or metres per second or per radian): a character whose file
        gives ``[character] lengths_for_height`` reads it as meant for a body that tall and scales it to its own
        standing height (docs/correspondence.md, "Decisions relative to the body").
    parameters : sequence of Parameter, optional
        A table of options that belong together (see the module): its keys, each checked as a component's own.
        The parameter's type is then ``dict`` and its value the table with every default filled in; ``default``,
        if given, is a table of defaults in place of the inner parameters' own.
    """

    name: str
    type: type = dict
    default: Any = REQUIRED
    doc: str = ""
    minimum: float | None = None
    maximum: float | None = None
    choices: Sequence[Any] | None = None
    items: type | None = None
    check: Callable[[Any], str | None] | None = None
    seconds: bool = False
    length: bool = False
    parameters: Sequence[Parameter] = ()

    def __post_init__(self) -> None:
        if self.seconds and self.maximum is None:
            object.__setattr__(self, "maximum", MAX_SECONDS)
        if self.parameters:  # a table: its value is the table with every default filled in
            object.__setattr__(self, "parameters", tuple(self.parameters))
            given = {} if self.default is REQUIRED else self.default
            object.__setattr__(self, "default", validate_params(f"table {self.name!r}", self.parameters, given))

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    @property
    def table(self) -> bool:
        """Whether it is a table of parameters of its own (:attr:`parameters`)."""
        return bool(self.parameters)

    def describe(self, *, article: bool = False) -> str:
        """One line: type, bounds and default (``article`` starts it with "a"/"an" and leaves the default out)."""
        if self.table:
            return "a table of " + ", ".join(p.name for p in self.parameters) if article else \
                "table of " + ", ".join(p.name for p in self.parameters)
        text = _TYPE_NAMES[self.type] if article else _TYPE_NAMES[self.type].split(" ", 1)[1]
        if self.items is not None:
            text += f" of {_TYPE_NAMES[self.items].split(' ', 1)[1]}s"
        if self.type in (int, float):
            lo, hi = self.bounds
            text += f" in [{_bound(lo, self.type)}, {_bound(hi, self.type)}]"
        if self.choices is not None:
            text += " (one of " + ", ".join(map(repr, self.choices)) + ")"
        if not article:
            text += ", required" if self.required else f", default {self.default!r}"
            if self.length:
                text += ", a length (scaled to the body with lengths_for_height)"
        return text

    @property
    def bounds(self) -> tuple[float, float]:
        """The inclusive range :meth:`coerce` holds a number parameter to (what ``likeme plugins --params`` shows).

        Its own ``minimum`` and ``maximum`` (a duration's maximum an hour, :data:`MAX_SECONDS`); where it gives
        none, a number is at most :data:`MAX_MAGNITUDE` in size on that side and an integer at most :data:`MAX_INT`.
        Not a number parameter: a ``TypeError``."""
        if self.type not in (int, float) or self.table:
            raise TypeError(f"parameter {self.name!r} is not a number")
        implicit = MAX_MAGNITUDE if self.type is float else MAX_INT
        return (-implicit if self.minimum is None else self.minimum,
                implicit if self.maximum is None else self.maximum)

    def coerce(self, value: Any) -> Any:
        """Return the checked value (ints widened to float) or raise :class:`ConfigError`.

        A NaN or infinite number anywhere in the value (in an array or table too) is refused: every number a
        parameter takes is finite. A table (:attr:`parameters`) is checked key by key and comes back with its
        defaults filled in; an error's key is then the path inside it (``("dwell", "speed")``).
        """
        if self.table:
            value = _check_type(value, dict, self.name, self._expected())
            try:
                return validate_params(f"table {self.name!r}", self.parameters, value)
            except ConfigError as err:
                raise err.within(prefix=(self.name,)) from None
        value = _check_type(value, self.type, self.name, self._expected())
        where = _non_finite(value)
        if where is not None:
            path, number = where
            raise ConfigError(f"value {number!r} is not a finite number", key=(self.name, *path),
                              expected=self._expected() if not path else "finite numbers")
        if self.items is not None:
            value = [_check_type(v, self.items, i, self._expected()) for i, v in enumerate(value)]
        if self.type in (int, float):
            lo, hi = self.bounds
            if not lo <= value <= hi:
                if value > hi and self.maximum is None or value < lo and self.minimum is None:
                    raise ConfigError(f"value {value!r} too large", key=(self.name,),
                                      expected=f"{self._expected()} (no parameter without bounds of its own takes more)")
                raise ConfigError(f"value {value!r} out of range", key=(self.name,), expected=self._expected())
        if self.choices is not None and value not in self.choices:
            raise ConfigError(
                f"value {value!r} not allowed",
                key=(self.name,),
                expected=self._expected(),
                available=[str(c) for c in self.choices],
            )
        if self.check is not None:
            problem = self.check(value)
            if problem:
                raise ConfigError(problem, key=(self.name,), expected=self._expected())
        return value

    def _expected(self) -> str:
        return self.describe(article=True)




def finite_number(value: Any) -> float | None:
    """``value`` as a float if it is a number (not a bool) whose float is finite, else ``None``: NaN, infinities,
    strings and integers too large for a float (``10**400``) all give ``None``, never an exception."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        number = float(value)
    except OverflowError:
        return None
    return number if math.isfinite(number) else None


def _non_finite(value: Any) -> tuple[tuple[str | int, ...], float] | None:
    """The key path (relative to ``value``) and value of its first NaN or infinite number, or ``None``."""
    stack: list[tuple[tuple[str | int, ...], Any]] = [((), value)]
    while stack:
        path, item = stack.pop()
        if isinstance(item, float) and not math.isfinite(item):
            return path, item
        if isinstance(item, Mapping):
            stack.extend(((*path, k), v) for k, v in reversed(list(item.items())))
        elif isinstance(item, (list, tuple)):
            stack.extend(((*path, i), v) for i, v in reversed(list(enumerate(item))))
    return None


def _check_type(value: Any, kind: type, key: str | int, expected: str) -> Any:
    ok = isinstance(value, kind) and not (kind in (int, float) and isinstance(value, bool))
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        if finite_number(value) is None:
            raise ConfigError(f"number too large ({str(value)[:20]}...)", key=(key,) if isinstance(key, str) else
                              ("", key), expected=expected)
        return float(value)
    if kind is int and isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INT:
        raise ConfigError(f"integer too large ({str(value)[:20]}...)", key=(key,) if isinstance(key, str) else ("", key),
                          expected=f"{expected} (at most {MAX_INT} in size)")
    if kind is dict:
        ok = isinstance(value, Mapping)
    if not ok:
        raise ConfigError(
            f"wrong type {type(value).__name__} (value {value!r})",
            key=(key,) if isinstance(key, str) else ("", key),
            expected=expected,
        )
    return value


def validate_params(owner: str, parameters: Sequence[Parameter], values: Mapping[str, Any]) -> dict[str, Any]:
    """Check ``values`` against ``parameters`` and fill in defaults.

    Parameters
    ----------
    owner : str
        Who the parameters belong to, for messages (``"segmenter 'hub-threshold'"``).
    parameters : sequence of Parameter
    values : mapping
        The given values (a TOML table without the ``plugin`` key).

    Returns
    -------
    dict
        Every parameter name mapped to its checked value.

    Raises
    ------
    ConfigError
        With the key relative to the table.
    """
    known = {p.name: p for p in parameters}
    for key in values:
        if key not in known:
            raise ConfigError(
                f"unknown parameter {key!r} for {owner}",
                key=(key,),
                expected=f"a parameter of {owner}",
                available=sorted(known),
            )
    out: dict[str, Any] = {}
    for p in parameters:
        if p.name in values:
            try:
                out[p.name] = p.coerce(values[p.name])
            except ConfigError as err:
                if err.key[:1] == ("",):  # list element: place it under the parameter name
                    err = ConfigError(
                        err.problem, key=(p.name, *err.key[1:]), expected=err.expected, available=err.available
                    )
                elif p.table:
                    err = of_owner(err, owner)
                raise err from None
        elif p.required:
            raise ConfigError(f"missing required parameter of {owner}", key=(p.name,), expected=p._expected())
        else:
            out[p.name] = dict(p.default) if p.table else p.default
    return out


def of_owner(err: ConfigError, owner: str) -> ConfigError:
    """An error inside a parameter's table (``... for table 'dwell'``) said to be of ``owner``'s table."""
    problem, _, table = err.problem.rpartition(" for table ")
    if not problem:
        return err
    expected = err.expected.replace(f"of table {table}", f"of table {table} of {owner}") if err.expected else None
    return ConfigError(f"{problem} in table {table} of {owner}", key=err.key, expected=expected,
                       available=err.available)


def length_names(parameters: Sequence[Parameter]) -> list[tuple[str, ...]]:
    """The key paths of every parameter declared a ``length``, inside tables too (``("dwell", "radius")``)."""
    out: list[tuple[str, ...]] = []
    for p in parameters:
        if p.table:
            out.extend((p.name, *inner) for inner in length_names(p.parameters))
        elif p.length:
            out.append((p.name,))
    return out


def scaled(values: Mapping[str, Any], lengths: Sequence[tuple[str, ...]], factor: float) -> dict[str, Any]:
    """``values`` (checked parameters) with the value at each key path of ``lengths`` multiplied by ``factor``."""
    out = dict(values)
    for path in lengths:
        if len(path) == 1:
            out[path[0]] = out[path[0]] * factor
        else:
            out[path[0]] = scaled(out[path[0]], [path[1:]], factor)
    return out


def flat_parameters(parameters: Sequence[Parameter], prefix: tuple[str, ...] = ()
                    ) -> list[tuple[tuple[str, ...], Parameter]]:
    """Every parameter with its key path, the parameters of a table after it (depth first, in declaration order):
    what ``likeme plugins --params`` and the parameter reference list."""
    out: list[tuple[tuple[str, ...], Parameter]] = []
    for p in parameters:
        out.append(((*prefix, p.name), p))
        if p.table:
            out.extend(flat_parameters(p.parameters, (*prefix, p.name)))
    return out
