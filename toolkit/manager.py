"""The plugin manager: loads the ``likeme`` entry-point group and indexes the components plugins register.

Built-in plugins are ordinary entries of that group, declared by the ``likeme``
distribution's own ``pyproject.toml``; a third-party distribution declares its
own entries the same way and is loaded by the same code.

Environment variables:

``LIKEME_DISABLE_PLUGIN_AUTOLOAD=1``
    Load only the entries of the ``likeme`` distribution itself (the built-ins);
    third-party entries are skipped.
``LIKEME_TRACE_HOOKS=1``
    Print every hook call and its result to standard error.

Nothing is loaded at import time: call :func:`create_plugin_manager`.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import metadata
from types import ModuleType
from typing import Any

import pluggy

from toolkit import hookspecs
from toolkit.components import KINDS, Component
from toolkit.errors import ConfigError, PluginError

__all__ = [
    "ENTRY_POINT_GROUP",
    "DISTRIBUTION",
    "PluginManager",
    "PluginInfo",
    "ComponentInfo",
    "Registry",
    "create_plugin_manager",
]

ENTRY_POINT_GROUP = "likeme"
DISTRIBUTION = "likeme"
ENV_DISABLE_AUTOLOAD = "LIKEME_DISABLE_PLUGIN_AUTOLOAD"
ENV_TRACE = "LIKEME_TRACE_HOOKS"

REGISTER_HOOKS: dict[str, str] = {
    "perception": "likeme_register_perceptions",
    "segmenter": "likeme_register_segmenters",
    "matcher": "likeme_register_matchers",
    "motor": "likeme_register_motor_systems",
    "action": "likeme_register_action_systems",
    "trigger": "likeme_register_triggers",
    "view": "likeme_register_views",
}
"""The registration hook of each component kind (keys as in :data:`toolkit.components.KINDS`)."""

_NAME = re.compile(r"^[a-z][a-z0-9]*(?:[-_][a-z0-9]+)*$")


@dataclass(frozen=True)
class PluginInfo:
    """A loaded plugin: its registered name, module and the distribution it came from."""

    name: str
    module: str
    distribution: str
    version: str


@dataclass(frozen=True)
class ComponentInfo:
    """A registered component class and the plugin that registered it."""

    kind: str
    name: str
    cls: type[Component]
    plugin: PluginInfo


class Registry:
    """Components by kind and name, collected from the ``likeme_register_*`` hooks."""

    def __init__(self, components: Iterable[ComponentInfo]) -> None:
        self._by_kind: dict[str, dict[str, ComponentInfo]] = {kind: {} for kind in KINDS}
        for info in components:
            self._by_kind[info.kind][info.name] = info

    def names(self, kind: str) -> list[str]:
        """Registered names of one kind, sorted."""
        return sorted(self._by_kind[kind])

    def infos(self, kind: str) -> list[ComponentInfo]:
        return [self._by_kind[kind][n] for n in self.names(kind)]

    def get(self, kind: str, name: str) -> type[Component]:
        """The class registered as ``name``; :class:`ConfigError` listing the registered names if none."""
        try:
            return self._by_kind[kind][name].cls
        except KeyError:
            label = KINDS[kind].kind
            raise ConfigError(
                f"unknown {label} {name!r}", expected=f"the name of a registered {label}", available=self.names(kind)
            ) from None

    def info(self, kind: str, name: str) -> ComponentInfo:
        self.get(kind, name)
        return self._by_kind[kind][name]


class PluginManager(pluggy.PluginManager):
    """A pluggy manager for the ``likeme`` hooks that remembers where each plugin came from."""

    def __init__(self) -> None:
        super().__init__(hookspecs.PROJECT)
        self.add_hookspecs(hookspecs)
        self.plugin_infos: dict[str, PluginInfo] = {}
        self.skipped: list[PluginInfo] = []
        self._registry: Registry | None = None

    # -- loading -------------------------------------------------------------------

    def load_entry_points(self, *, third_party: bool = True) -> None:
        """Register every entry of the ``likeme`` group (only the built-ins if ``third_party`` is false)."""
        seen: dict[str, PluginInfo] = {}
        for ep in sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=_builtin_first):
            dist = ep.dist.metadata["Name"] if ep.dist is not None else "(unknown)"
            version = ep.dist.version if ep.dist is not None else "?"
            info = PluginInfo(ep.name, ep.value, dist, version)
            if info.name in seen:
                if seen[info.name].module == info.module:  # the same distribution found twice on sys.path
                    continue
                raise PluginError(
                    ep.name,
                    "entry point",
                    f"name registered by both {seen[ep.name].distribution} ({seen[ep.name].module}) "
                    f"and {dist} ({ep.value}); plugin names must be unique",
                )
            seen[info.name] = info
            if not third_party and _normalise(dist) != DISTRIBUTION:
                self.skipped.append(info)
                continue
            try:
                module = ep.load()
            except Exception as exc:  # a broken third-party import must name itself
                raise PluginError(ep.name, f"import of {ep.value} ({dist})", f"{type(exc).__name__}: {exc}") from exc
            self.register_plugin(module, info)

    def register_plugin(self, plugin: ModuleType | object, info: PluginInfo) -> None:
        """Register one plugin object under ``info.name`` (used for entry points and by tests)."""
        try:
            self.register(plugin, name=info.name)
            self.check_pending()  # a hook name that is not a likeme hook (a typo) is an error
        except (pluggy.PluginValidationError, ValueError) as exc:
            if self.is_registered(plugin):
                self.unregister(plugin)
            raise PluginError(info.name, "registration", str(exc)) from exc
        self.plugin_infos[info.name] = info
        self._registry = None

    # -- components ----------------------------------------------------------------

    @property
    def registry(self) -> Registry:
        """Every component registered by the loaded plugins (collected once, then cached)."""
        if self._registry is None:
            self._registry = Registry(self._collect())
        return self._registry

    def _collect(self) -> list[ComponentInfo]:
        found: dict[tuple[str, str], ComponentInfo] = {}
        for kind, hook_name in REGISTER_HOOKS.items():
            caller = getattr(self.hook, hook_name)
            for impl in caller.get_hookimpls():  # registration order
                info = self.plugin_infos.get(impl.plugin_name) or PluginInfo(
                    impl.plugin_name, repr(impl.plugin), "(registered in Python)", ""
                )
                try:
                    classes = impl.function()
                except Exception as exc:
                    raise PluginError(info.name, hook_name, f"{type(exc).__name__}: {exc}") from exc
                for cls in _check_registered(classes, kind, info, hook_name):
                    key = (kind, cls.name)
                    if key in found:
                        other = found[key].plugin
                        raise PluginError(
                            info.name,
                            hook_name,
                            f"{KINDS[kind].kind} name {cls.name!r} is already registered by plugin "
                            f"{other.name!r} ({other.distribution}); names must be unique",
                        )
                    found[key] = ComponentInfo(kind, cls.name, cls, info)
        return list(found.values())


def _check_registered(classes: Any, kind: str, info: PluginInfo, hook_name: str) -> list[type[Component]]:
    base = KINDS[kind]
    if classes is None:
        return []
    if not isinstance(classes, (list, tuple)):
        raise PluginError(info.name, hook_name, f"returned {classes!r}, expected a list of classes")
    for cls in classes:
        if not (isinstance(cls, type) and issubclass(cls, base)):
            raise PluginError(info.name, hook_name, f"returned {cls!r}, expected a subclass of {base.__qualname__}")
        if not isinstance(cls.name, str) or not _NAME.match(cls.name):
            raise PluginError(
                info.name,
                hook_name,
                f"{cls.__qualname__}.name is {cls.name!r}, expected lower-case words joined by '-' (like 'hub-threshold')",
            )
        if getattr(cls, "__abstractmethods__", None):
            missing = ", ".join(sorted(cls.__abstractmethods__))
            raise PluginError(info.name, hook_name, f"{cls.__qualname__} does not implement {missing}")
    return list(classes)


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _builtin_first(ep: metadata.EntryPoint) -> tuple[int, str]:
    dist = ep.dist.metadata["Name"] if ep.dist is not None else ""
    return (0 if _normalise(dist) == DISTRIBUTION else 1, ep.name)


def create_plugin_manager(
    *,
    autoload: bool | None = None,
    plugins: Iterable[tuple[str, object]] = (),
    trace: bool | None = None,
) -> PluginManager:
    """A fresh plugin manager with the built-ins, the third-party entry points and ``plugins``.

    Parameters
    ----------
    autoload : bool, optional
        Load third-party entry points. Default: true unless ``LIKEME_DISABLE_PLUGIN_AUTOLOAD`` is set.
    plugins : iterable of (name, object)
        Further plugin objects to register after the entry points (tests use this).
    trace : bool, optional
        Trace hook calls to standard error. Default: whether ``LIKEME_TRACE_HOOKS`` is set.
    """
    if autoload is None:
        autoload = os.environ.get(ENV_DISABLE_AUTOLOAD, "") in ("", "0")
    if trace is None:
        trace = os.environ.get(ENV_TRACE, "") not in ("", "0")
    pm = PluginManager()
    if trace:
        pm.trace.root.setwriter(lambda text: sys.stderr.write(text))
        pm.enable_tracing()
    pm.load_entry_points(third_party=autoload)
    if not any(_normalise(i.distribution) == DISTRIBUTION for i in pm.plugin_infos.values()):
        raise PluginError(
            DISTRIBUTION,
            "entry points",
            "no built-in plugins found: install the project (pip install -e .) so that its entry points exist",
        )
    for name, plugin in plugins:
        pm.register_plugin(plugin, PluginInfo(name, getattr(plugin, "__name__", repr(plugin)), "(registered in Python)", ""))
    return pm
