"""The plugin manager: loads the ``likeme`` entry-point group and indexes the components plugins register.

Built-in plugins are ordinary entries of that group, declared by the ``likeme``
distribution's own ``pyproject.toml``; a third-party distribution declares its
own entries the same way and is loaded by the same code.

Environment variables:

``LIKEME_DISABLE_PLUGIN_AUTOLOAD=1``
    Load only the entries of the ``likeme`` distribution itself (the built-ins);
    third-party entries are skipped.

A third-party entry point that fails to import or to register does not stop likeme: it is left out, recorded in
:attr:`PluginManager.failed`, and one warning line on standard error names the entry point, its distribution,
the error, and ``LIKEME_DISABLE_PLUGIN_AUTOLOAD=1``. Every command goes on without it (``validate`` included);
only a component it would have registered is missing, and naming one is the usual "unknown ..." error, which then
also names the plugin that failed. ``likeme plugins`` lists it as failed. A built-in that fails is an error.
``LIKEME_TRACE_HOOKS=1``
    Print every hook call and its result to standard error.

Every hook call goes through pluggy (run events, registration, loading, commands), so tracing shows all of them.
A hook implementation that raises is handled in one place, a hook-call monitor (:meth:`PluginManager.failure_policy`):
by default it becomes a :class:`~toolkit.errors.PluginError` naming the plugin and the hook; under the ``"skip"``
policy a world runs with (``likeme run --keep-going``) the plugin is unregistered, the failure reported, and the
implementations not yet called are called.

Nothing is loaded at import time: call :func:`create_plugin_manager`. The ``likeme`` command makes a *lazy* one
(``create_plugin_manager(lazy=True)``): it reads the entry points (metadata only) and imports only the plugins that
add commands, builds its parser, and imports the others when a command runs (:meth:`PluginManager.load_all`), so
that ``likeme --help`` imports no plugin that only registers components. Which plugins add commands: a distribution
names them in a second group, ``likeme.commands`` (``NAME = "module"``, the same NAME as in ``likeme``); a
distribution that declares no ``likeme.commands`` entry has every ``likeme`` entry imported for the command line,
as before. The order plugins are registered in (and so the order of hook calls) does not depend on this.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from importlib import metadata
from types import ModuleType, TracebackType
from typing import TYPE_CHECKING, Any

import pluggy

from toolkit import hookspecs
from toolkit.errors import ConfigError, LikemeError, PluginError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.components import Component

__all__ = [
    "ENTRY_POINT_GROUP",
    "COMMANDS_GROUP",
    "DISTRIBUTION",
    "PluginManager",
    "PluginInfo",
    "ComponentInfo",
    "Registry",
    "create_plugin_manager",
]

ENTRY_POINT_GROUP = "likeme"
COMMANDS_GROUP = "likeme.commands"
DISTRIBUTION = "likeme"
ENV_DISABLE_AUTOLOAD = "LIKEME_DISABLE_PLUGIN_AUTOLOAD"
ENV_TRACE = "LIKEME_TRACE_HOOKS"

REGISTER_HOOKS: dict[str, str] = {
    "perception": "likeme_register_perceptions",
    "correspondence": "likeme_register_correspondences",
    "segmenter": "likeme_register_segmenters",
    "matcher": "likeme_register_matchers",
    "motor": "likeme_register_motor_systems",
    "action": "likeme_register_action_systems",
    "layer": "likeme_register_layers",
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
    """Components by kind and name, collected from the ``likeme_register_*`` hooks.

    ``failed``: third-party plugins that failed to load; an unknown name's error mentions them.
    """

    def __init__(self, components: Iterable[ComponentInfo], failed: Sequence[PluginInfo] = ()) -> None:
        from toolkit.components import KINDS

        self.failed = tuple(failed)
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
            from toolkit.components import KINDS

            label = KINDS[kind].kind
            expected = f"the name of a registered {label}"
            if self.failed:
                expected += " (" + ", ".join(f"plugin {i.name!r} of {i.distribution} failed to load"
                                             for i in self.failed) + ")"
            raise ConfigError(f"unknown {label} {name!r}", expected=expected, available=self.names(kind)) from None

    def info(self, kind: str, name: str) -> ComponentInfo:
        self.get(kind, name)
        return self._by_kind[kind][name]


Failed = Callable[[str, str, PluginError], None]
"""``failed(plugin name, hook name, error)``: told of a plugin dropped under the ``"skip"`` policy."""


class PluginManager(pluggy.PluginManager):
    """A pluggy manager for the ``likeme`` hooks that remembers where each plugin came from.

    It monitors every hook call (:meth:`failure_policy`): a failing implementation is named, or skipped.
    """

    def __init__(self) -> None:
        super().__init__(hookspecs.PROJECT)
        self.add_hookspecs(hookspecs)
        self.plugin_infos: dict[str, PluginInfo] = {}
        self.skipped: list[PluginInfo] = []
        self.failed: list[tuple[PluginInfo, PluginError]] = []
        self._registry: Registry | None = None
        self._policies: list[tuple[str, Failed | None]] = []
        self._entries: list[tuple[PluginInfo, metadata.EntryPoint]] | None = None  # found, in loading order
        self._third_party = True
        self._imported: dict[str, object | None] = {}  # entry name -> module (None: a third-party one that failed)
        self._early: list[str] = []  # registered before the others, for the command line
        self._loaded = False
        self._extra: list[tuple[str, object]] = []  # create_plugin_manager(plugins=...), registered after the entries
        self.tracing = False
        self.add_hookcall_monitoring(lambda *_: None, self._after_hookcall)

    def enable_tracing(self) -> Callable[[], None]:
        """Trace every hook call (pluggy's tracing); every run event is then called, implemented or not."""
        self.tracing = True
        undo = super().enable_tracing()

        def stop() -> None:
            self.tracing = False
            undo()

        return stop

    # -- failures --------------------------------------------------------------------

    def failure_policy(self, policy: str, failed: Failed | None = None) -> FailurePolicy:
        """A context manager: hook calls made inside its ``with`` block follow ``policy`` (it may be entered again).

        ``"stop"`` (also the policy outside any block): an implementation that raises anything but a likeme error
        becomes a :class:`PluginError` naming its plugin and the hook. ``"skip"``: its plugin is unregistered,
        ``failed(plugin, hook, error)`` is told, and the implementations that had not been called yet are called.
        """
        if policy not in ("stop", "skip"):
            raise ValueError("a failure policy is 'stop' or 'skip'")
        return FailurePolicy(self._policies, (policy, failed))

    def _after_hookcall(self, outcome: pluggy.Result, hook_name: str, impls: Sequence[pluggy.HookImpl],
                        kwargs: dict[str, Any]) -> None:
        exc = outcome.exception
        if not isinstance(exc, Exception):
            return
        culprit = _culprit(exc.__traceback__, impls)
        name = culprit.plugin_name if culprit is not None else "(a plugin)"
        policy, failed = self._policies[-1] if self._policies else ("stop", None)
        if policy == "skip" and culprit is not None:
            error = exc if isinstance(exc, PluginError) else PluginError(name, hook_name, f"{type(exc).__name__}: {exc}")
            self.unregister(culprit.plugin)
            if failed is not None:
                failed(name, hook_name, error)
            # pluggy calls the implementations last to first: those before the culprit in the list had not run
            waiting = [impl for impl in impls[: list(impls).index(culprit)] if self.is_registered(impl.plugin)]
            outcome.force_result(self._inner_hookexec(hook_name, waiting, kwargs, False) if waiting else [])
        elif not isinstance(exc, LikemeError):
            error = PluginError(name, hook_name, f"{type(exc).__name__}: {exc}")
            error.__cause__ = exc
            outcome.force_exception(error)

    # -- loading -------------------------------------------------------------------

    def find_entry_points(self, *, third_party: bool = True) -> None:
        """Read the ``likeme`` group, built-ins first (metadata only: no plugin is imported); once per manager.

        Third-party entries are left out (in :attr:`skipped`) if ``third_party`` is false. Two distributions
        registering one name is an error.
        """
        if self._entries is not None:
            return
        self._third_party = third_party
        seen: dict[str, PluginInfo] = {}
        entries = []
        found = metadata.entry_points(group=ENTRY_POINT_GROUP)
        known: dict[int, tuple[str, str]] = {}  # the distributions of ``found``, alive while it is
        for ep in sorted(found, key=lambda ep: _builtin_first(ep, known)):
            dist, version = _distribution(ep, known)
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
            entries.append((info, ep))
        self._entries = entries

    def entries_fingerprint(self) -> str | None:
        """A digest of everything a listing of the registered components depends on, read without importing any
        plugin: every entry found (name, module, distribution, version), the size and modification time of every
        source file of its module (a package's files under it), of the core (:mod:`toolkit`), the Python version and
        whether third-party entries are left out. ``None`` when it cannot be told (a manager that never looked for
        entries, plugins registered in Python, a module whose files cannot be found)."""
        import hashlib
        from importlib.util import find_spec
        from pathlib import Path

        if self._entries is None or self._extra:
            return None
        entries = {info.name for info, _ in self._entries}
        if any(name not in entries for name, _ in self.list_name_plugin()):  # registered in Python
            return None
        digest = hashlib.sha256(f"{sys.version}|{self._third_party}".encode())
        folders = [Path(__file__).resolve().parent]
        files: list[Path] = []
        for info, _ in self._entries:
            digest.update(f"|{info.name}={info.module}@{info.distribution}=={info.version}".encode())
            try:
                spec = find_spec(info.module.split(":")[0])
            except (ImportError, ValueError, AttributeError):
                return None
            if spec is None or not spec.origin or not spec.has_location:
                return None
            if spec.submodule_search_locations:
                folders.extend(Path(f) for f in spec.submodule_search_locations)
            else:
                files.append(Path(spec.origin))
        for folder in dict.fromkeys(folders):
            files.extend(sorted(folder.rglob("*.py")))
        for skipped in self.skipped:
            digest.update(f"|skipped {skipped.name}".encode())
        for path in files:
            try:
                stat = path.stat()
            except OSError:
                return None
            digest.update(f"|{path}:{stat.st_size}:{stat.st_mtime_ns}".encode())
        return digest.hexdigest()

    def load_entry_points(self, *, third_party: bool = True) -> None:
        """Import and register every entry of the ``likeme`` group (only the built-ins if ``third_party`` is false),
        in the order :meth:`find_entry_points` gives (built-ins first); those registered early for the command line
        (:meth:`load_command_plugins`) are registered again in that order."""
        self.find_entry_points(third_party=third_party)
        for name in self._early:  # hook calls go by registration order: the same as if all were loaded at once
            if self.get_plugin(name) is not None:
                self.unregister(name=name)
        self._early = []
        for info, ep in self._entries or []:
            self._load(info, ep)
        self._loaded = True
        for name, plugin in self._extra:  # create_plugin_manager(plugins=...): after the entry points
            self.register_plugin(plugin, PluginInfo(name, getattr(plugin, "__name__", repr(plugin)),
                                                    "(registered in Python)", ""))
        self._extra = []

    def load_command_plugins(self) -> None:
        """Import and register only the entries that may add commands (``likeme_register_commands``): those a
        distribution names in the ``likeme.commands`` group, and every entry of a distribution that names none
        there. Nothing for a manager that has loaded every entry or never looked for them."""
        if self._entries is None or self._loaded:
            return
        declared: dict[str, set[str]] = {}
        found = metadata.entry_points(group=COMMANDS_GROUP)
        known: dict[int, tuple[str, str]] = {}
        for ep in found:
            dist = _normalise(_distribution(ep, known)[0])
            declared.setdefault(dist, set()).add(ep.name)
        for info, ep in self._entries:
            names = declared.get(_normalise(info.distribution))
            if (names is None or info.name in names) and self._load(info, ep):
                self._early.append(info.name)

    def load_all(self) -> None:
        """Load the entries a lazy manager (``create_plugin_manager(lazy=True)``) left for later; nothing for a
        manager that loaded them, or was made without entry points."""
        if self._entries is not None and not self._loaded:
            self.load_entry_points(third_party=self._third_party)

    def _load(self, info: PluginInfo, ep: metadata.EntryPoint) -> bool:
        """Import one entry point's module (once) and register it; whether it is registered. A built-in that fails
        is an error; a third-party one is left out, recorded and announced once (:meth:`_fail`)."""
        if self.get_plugin(info.name) is not None:
            return False
        builtin = _normalise(info.distribution) == DISTRIBUTION
        if info.name not in self._imported:
            try:
                self._imported[info.name] = ep.load()
            except Exception as exc:  # a broken import must name itself
                error = PluginError(info.name, f"import of {info.module} ({info.distribution})",
                                    f"{type(exc).__name__}: {exc}")
                if builtin:
                    raise error from exc
                self._imported[info.name] = None
                self._fail(info, error)
        module = self._imported[info.name]
        if module is None:
            return False
        try:
            self.register_plugin(module, info)
        except PluginError as error:
            if builtin:
                raise
            self._imported[info.name] = None
            self._fail(info, error)
            return False
        return True

    def _fail(self, info: PluginInfo, error: PluginError) -> None:
        """A third-party entry point that failed: left out, recorded and announced on one warning line."""
        self.failed.append((info, error))
        self._registry = None
        sys.stderr.write(f"likeme: warning: {error}; going on without plugin {info.name!r} of distribution "
                         f"{info.distribution} {info.version} (entry point {info.name} = {info.module}); set "
                         f"{ENV_DISABLE_AUTOLOAD}=1 to load only the built-in plugins\n")

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

    # -- run events ------------------------------------------------------------------

    def announce(self, hook_name: str, **kwargs: Any) -> None:
        """Call a run-event hook (through pluggy: traced, and under the failure policy in force). A hook nothing
        implements is not called unless tracing is on, which shows every call."""
        caller = getattr(self.hook, hook_name)
        if self.tracing or caller.get_hookimpls():
            caller(**kwargs)

    # -- components ----------------------------------------------------------------

    @property
    def registry(self) -> Registry:
        """Every component registered by the loaded plugins (collected once, then cached)."""
        self.load_all()  # a lazy manager's components are those of every plugin, as an eager one's
        if self._registry is None:
            self._registry = Registry(self._collect(), [info for info, _ in self.failed])
        return self._registry

    def _collect(self) -> list[ComponentInfo]:
        """Each plugin's registration hooks called through pluggy (one plugin at a time, so that every class is
        credited to the plugin that returned it)."""
        from toolkit.components import KINDS

        found: dict[tuple[str, str], ComponentInfo] = {}
        for kind, hook_name in REGISTER_HOOKS.items():
            impls = getattr(self.hook, hook_name).get_hookimpls()  # registration order
            for impl in impls:
                info = self.plugin_infos.get(impl.plugin_name) or PluginInfo(
                    impl.plugin_name, repr(impl.plugin), "(registered in Python)", ""
                )
                others = [other.plugin for other in impls if other is not impl]
                results = self.subset_hook_caller(hook_name, remove_plugins=others)()
                for cls in _check_registered(results[0] if results else None, kind, info, hook_name):
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


class FailurePolicy:
    """The context manager :meth:`PluginManager.failure_policy` returns (reusable: a world enters one every step)."""

    def __init__(self, stack: list, policy: tuple[str, Failed | None]) -> None:
        self._stack, self._policy = stack, policy

    def __enter__(self) -> None:
        self._stack.append(self._policy)

    def __exit__(self, *exc: object) -> None:
        self._stack.pop()


def _culprit(tb: TracebackType | None, impls: Sequence[pluggy.HookImpl]) -> pluggy.HookImpl | None:
    """The implementation whose frame is the outermost in a traceback: the one that raised (or called what did)."""
    codes: dict[Any, list[pluggy.HookImpl]] = {}
    for impl in impls:
        code = getattr(impl.function, "__code__", None)
        if code is not None:
            codes.setdefault(code, []).append(impl)
    while tb is not None:
        found = codes.get(tb.tb_frame.f_code)
        if found:
            if len(found) == 1:
                return found[0]
            this = tb.tb_frame.f_locals.get("self")  # one method, several instances registered
            return next((i for i in found if getattr(i.function, "__self__", None) is this), found[0])
        tb = tb.tb_next
    return None


def _check_registered(classes: Any, kind: str, info: PluginInfo, hook_name: str) -> list[type[Component]]:
    from toolkit.components import KINDS

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
        _check_declared(cls, info, hook_name)
    return list(classes)


def _check_declared(cls: type, info: PluginInfo, hook_name: str) -> None:
    """A declared capability must be implemented, and an implemented one declared (the runtime goes by the
    declaration)."""
    from toolkit.components import Matcher, Perception

    pairs = []
    if issubclass(cls, Matcher):
        pairs.append(("streaming", cls.streaming, "observe", cls.observe is not Matcher.observe))
    if issubclass(cls, Perception):
        pairs.append(("watches_recordings", cls.watches_recordings, "perceive_pose",
                      cls.perceive_pose is not Perception.perceive_pose))
    for flag, declared, method, implemented in pairs:
        if declared and not implemented:
            raise PluginError(info.name, hook_name, f"{cls.__qualname__} declares {flag} = True but does not "
                              f"implement {method}")
        if implemented and not declared:
            raise PluginError(info.name, hook_name, f"{cls.__qualname__} implements {method} but does not declare "
                              f"{flag} = True")


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _distribution(ep: metadata.EntryPoint, known: dict[int, tuple[str, str]] | None = None) -> tuple[str, str]:
    """The name and version of an entry point's distribution. ``known`` (distribution id -> name and version, kept
    by the caller while the entry points live) parses each distribution's metadata once, not once per entry point:
    every entry point of one distribution shares its ``dist``."""
    dist = ep.dist
    if dist is None:
        return "(unknown)", "?"
    if known is not None and id(dist) in known:
        return known[id(dist)]
    meta = dist.metadata
    found = (meta["Name"], meta["Version"])
    if known is not None:
        known[id(dist)] = found
    return found


def _builtin_first(ep: metadata.EntryPoint, known: dict[int, tuple[str, str]] | None = None) -> tuple[int, str]:
    dist = _distribution(ep, known)[0] if ep.dist is not None else ""
    return (0 if _normalise(dist) == DISTRIBUTION else 1, ep.name)


def create_plugin_manager(
    *,
    autoload: bool | None = None,
    plugins: Iterable[tuple[str, object]] = (),
    trace: bool | None = None,
    lazy: bool = False,
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
    lazy : bool
        Find the entry points but import none: :meth:`PluginManager.load_command_plugins` imports those that add
        commands, :meth:`PluginManager.load_all` (or the first use of :attr:`PluginManager.registry`) the others
        (the ``likeme`` command's start-up). ``plugins`` are then registered by ``load_all``, after the entry points.
    """
    if autoload is None:
        autoload = os.environ.get(ENV_DISABLE_AUTOLOAD, "") in ("", "0")
    if trace is None:
        trace = os.environ.get(ENV_TRACE, "") not in ("", "0")
    pm = PluginManager()
    if trace:
        pm.trace.root.setwriter(lambda text: sys.stderr.write(text))
        pm.enable_tracing()
    pm.find_entry_points(third_party=autoload)
    if not any(_normalise(info.distribution) == DISTRIBUTION for info, _ in pm._entries or []):
        raise PluginError(
            DISTRIBUTION,
            "entry points",
            "no built-in plugins found: install the project (pip install -e .) so that its entry points exist",
        )
    pm._extra = [(name, plugin) for name, plugin in plugins]
    if not lazy:
        pm.load_all()
    return pm
