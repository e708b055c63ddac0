"""The fuzz worker: a long-lived process each case of ``likeme bench fuzz`` runs in (:class:`Worker`), under a
memory limit and a timeout, and what its answer means (:func:`classify`).

The worker runs the ``likeme`` command's ``main`` in its own process on one request at a time (:func:`run_one`):
anything that escapes it is a finding, located in the project's own code (not the libraries, not this harness); a
case that does not answer in time is a hang, located by the worker's stack dump; a case that exceeds the memory limit
ends its worker, and the next case starts a fresh one. :mod:`plugins.bench.fuzz` makes the cases and runs them here.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import select
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

from toolkit.errors import PluginError

__all__ = ["OUTCOMES", "Worker", "classify", "command_line", "permission_bits_hold", "run_one"]

ROOT = Path(__file__).resolve().parents[2]  # where the toolkit and plugins packages are (the source tree or site-packages)

OUTCOMES = ("ok", "documented", "traceback", "hang", "memory")
"""What a case can come to: it ran, it ended in one documented error, or a traceback, a hang, too much memory."""

OWN_CODE = ("toolkit", "plugins", "tests")
"""The folders of the project's own code: where a failure is located (not the libraries, not this harness)."""


def _own(filename: str) -> str:
    """``filename`` relative to the project if it is the project's own code (not this harness), else ''."""
    path = Path(filename).resolve()
    if path == Path(__file__).resolve() or ROOT not in path.parents:
        return ""
    rel = path.relative_to(ROOT)
    return rel.as_posix() if rel.parts[0] in OWN_CODE else ""


def _where(tb: Any) -> str:
    """The innermost frame of the traceback in the project's own code (``toolkit/x.py:12 in f``)."""
    found = ""
    for frame in traceback.extract_tb(tb):
        if own := _own(frame.filename):
            found = f"{own}:{frame.lineno} in {frame.name}"
    return found


def command_line() -> Any:
    """The ``likeme`` command's ``main``, found as the installed ``likeme`` script finds it (its console-scripts entry
    point): the command line is the floor above the plugins, so a benchmark of it starts it, never imports it."""
    from importlib.metadata import entry_points

    found = entry_points(group="console_scripts", name="likeme")
    if not found:
        raise PluginError("benchmark", "fuzz", "no likeme command installed (pip install -e .)")
    return next(iter(found)).load()


def run_one(request: dict[str, Any]) -> dict[str, Any]:
    """Run one case in this process (the worker's side): exit status, stderr, and any exception not handled."""
    from toolkit.errors import LikemeError

    main = command_line()

    out, err = io.StringIO(), io.StringIO()
    result: dict[str, Any] = {"rc": None, "exception": None, "message": "", "where": ""}
    cwd = os.getcwd()
    try:
        os.chdir(request["cwd"])
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            if request.get("argv") is not None:
                result["rc"] = main(request["argv"])
            else:
                from importlib import import_module

                module, function = request["call"].split(":")
                try:
                    getattr(import_module(module), function)(request["input"], fps=30.0)
                    result["rc"] = 0
                except LikemeError as exc:
                    print(f"likeme: error: {exc}", file=sys.stderr)
                    result["rc"] = 1
    except SystemExit as exc:  # argparse's exit: a status, a message already on stderr
        result["rc"] = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if exc.code is not None and not isinstance(exc.code, int):
            err.write(f"{exc.code}\n")
    except BaseException as exc:  # noqa: BLE001 - the point: anything that escapes is a finding
        result["exception"] = "MemoryError" if isinstance(exc, MemoryError) else type(exc).__name__  # numpy's too
        result["message"] = str(exc)[:300]
        result["where"] = _where(exc.__traceback__)
        err.write("".join(traceback.format_exception(exc))[-6000:])
        del exc
    finally:
        os.chdir(cwd)
    text = err.getvalue()
    result["stderr"] = text if len(text) <= 20000 else text[:10000] + "\n[...]\n" + text[-10000:]
    return result


_DAC_CAPABILITIES = (1 << 1) | (1 << 2) | (1 << 3)
"""``CAP_DAC_OVERRIDE``, ``CAP_DAC_READ_SEARCH`` and ``CAP_FOWNER`` (linux/capability.h): what lets root past a
file's permission bits."""


@contextlib.contextmanager
def permission_bits_hold(folder: str | Path) -> Any:
    """Permission bits stop this process (its calling thread) while inside, as they stop every user but root.

    A read-only folder for every user: a folder of mode 0o555 refuses a user's writes, but root passes every mode by
    its capabilities. Inside, root's :data:`_DAC_CAPABILITIES` are out of the thread's effective set (``capset(2)``:
    lowering one's own effective capabilities takes no privilege, and they come back from the permitted set on the
    way out), so the folder refuses root too; a user without them loses nothing. No mount, no namespace, nothing the
    CI may not allow. Yields ``"held"`` when a file cannot be created in ``folder`` inside, else why it can (not
    Linux, ``capset`` refused): the caller runs the case anyway and says so."""
    import ctypes

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32), ("inheritable", ctypes.c_uint32)]

    header, data, saved = Header(0x20080522, 0), (Data * 2)(), None  # _LINUX_CAPABILITY_VERSION_3: two words
    reason = ""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.capget(ctypes.byref(header), data) == 0:
            saved = data[0].effective
            data[0].effective = saved & ~_DAC_CAPABILITIES
            if libc.capset(ctypes.byref(header), data) != 0:
                reason, saved = f"capset refused ({os.strerror(ctypes.get_errno())})", None
        else:
            reason = f"capget refused ({os.strerror(ctypes.get_errno())})"
    except (OSError, AttributeError) as exc:  # no C library to ask, or no capget in it (not Linux)
        reason = f"no capabilities to lower ({exc})"
    try:
        try:
            handle, probe = tempfile.mkstemp(dir=folder, prefix=".likeme-probe-")
        except OSError:
            yield "held"
        else:
            os.close(handle)
            os.unlink(probe)
            yield f"a file could be created in the read-only folder ({reason or 'the permission bits did not hold'})"
    finally:
        if saved is not None:
            data[0].effective = saved
            libc.capset(ctypes.byref(header), data)


def _worker_main(memory_mb: int, warm: list[list[str]], stacks: str = "") -> None:
    """The worker process: read one JSON request a line, answer one JSON line on the protocol descriptor.

    With ``stacks``, ``SIGUSR1`` writes the worker's Python stack to that file (how a hang is located).
    """
    import faulthandler
    import resource

    if stacks:
        faulthandler.register(signal.SIGUSR1, file=open(stacks, "a", encoding="utf-8"), all_threads=False)  # noqa: SIM115
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past RLIMIT_FSIZE fails (EFBIG), it does not kill
    proto = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
    requests = os.fdopen(os.dup(0), "r", encoding="utf-8")
    devnull = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):  # the code under test reads nothing of the protocol and writes nowhere
        os.dup2(devnull, fd)
    with tempfile.TemporaryDirectory() as tmp:
        for argv in warm:  # import what the commands import before the memory limit and the first timeout
            run_one({"argv": argv, "cwd": tmp})
    page = os.sysconf("SC_PAGE_SIZE")
    proto.write(json.dumps({"ready": True}) + "\n")
    for line in requests:
        request = json.loads(line)
        if memory_mb > 0:  # the soft limit only: raised again for the next case (the code under test never does)
            try:
                with open("/proc/self/statm", encoding="ascii") as statm:
                    held = int(statm.read().split()[0]) * page
            except OSError:  # no /proc (not Linux): the limit counts from nothing
                held = 0
            resource.setrlimit(resource.RLIMIT_AS, (held + memory_mb * 1024 * 1024, resource.RLIM_INFINITY))
        if request.get("full"):  # a full disk for this case: every write to a file fails (EFBIG), none is cut short
            resource.setrlimit(resource.RLIMIT_FSIZE, (0, resource.RLIM_INFINITY))
        try:
            if request.get("read_only"):  # its folder and out/ are of mode 0o555: refused to root as well
                with permission_bits_hold(Path(request["cwd"]) / "out") as held:
                    result = run_one(request)
                result["read_only"] = held
            else:
                result = run_one(request)
        finally:
            resource.setrlimit(resource.RLIMIT_FSIZE, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
        try:
            proto.write(json.dumps(result) + "\n")
        except MemoryError:
            proto.write(json.dumps({"rc": None, "exception": "MemoryError", "message": "", "where": "",
                                    "stderr": "MemoryError"}) + "\n")
        if result["exception"] == "MemoryError":
            return  # a fresh worker for the next case


class Worker:
    """A long-lived ``python -m plugins.bench.fuzz_worker --worker`` process, restarted after a timeout or a crash."""

    def __init__(self, memory_mb: int, warm: list[list[str]] | None = None, *, start_timeout: float = 120.0) -> None:
        self._stacks = tempfile.NamedTemporaryFile(prefix="likeme-fuzz-stacks-", suffix=".txt", delete=False)  # noqa: SIM115
        self._stacks.close()
        self.memory_mb = memory_mb
        self.warm = warm or []
        self.start_timeout = start_timeout
        self.proc: subprocess.Popen | None = None
        self.restarts = 0

    def start(self) -> None:
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
                   MALLOC_ARENA_MAX="2", PYTHONHASHSEED="0", MPLBACKEND="Agg")
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        self.proc = subprocess.Popen([sys.executable, "-m", "plugins.bench.fuzz_worker", "--worker", str(self.memory_mb),
                                      json.dumps(self.warm), self._stacks.name], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, env=env, cwd=str(ROOT), start_new_session=True)
        answer = self._read(self.start_timeout)
        if not isinstance(answer, dict) or not answer.get("ready"):
            self.stop()
            raise RuntimeError(f"the fuzz worker did not start ({answer!r})")

    def _read(self, timeout: float) -> dict[str, Any] | str:
        """One answer line, or 'timeout', or 'died'."""
        assert self.proc is not None and self.proc.stdout is not None
        deadline = time.monotonic() + timeout
        buf = b""
        fd = self.proc.stdout.fileno()
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return "timeout"
            ready, _, _ = select.select([fd], [], [], left)
            if not ready:
                continue
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return "died"
            buf += chunk
            if buf.endswith(b"\n"):
                return json.loads(buf)

    def close(self) -> None:
        """Stop the worker for good."""
        self.stop()
        Path(self._stacks.name).unlink(missing_ok=True)

    def _stack(self) -> str:
        """The innermost frame of the project's code where the (hung) worker is now, from its stack dump."""
        assert self.proc is not None
        path = Path(self._stacks.name)
        before = path.stat().st_size
        try:
            os.kill(self.proc.pid, signal.SIGUSR1)
        except ProcessLookupError:
            return ""
        deadline = time.monotonic() + 2.0
        while path.stat().st_size == before and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.1)
        with path.open(encoding="utf-8", errors="replace") as handle:
            handle.seek(before)
            dump = handle.read()
        for file, line, function in re.findall(r'File "([^"]+)", line (\d+) in (\S+)', dump):  # innermost first
            if own := _own(file):
                return f"{own}:{line} in {function}"
        return ""

    def stop(self) -> None:
        if self.proc is None:
            return
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.proc.pid, signal.SIGKILL)  # the worker's own session: it and any child it started
        self.proc.wait()
        for stream in (self.proc.stdin, self.proc.stdout):
            with contextlib.suppress(OSError):
                stream.close()
        self.proc = None

    def run(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        """Run one request; a timeout or a death of the worker is reported as such, and the worker restarted."""
        if self.proc is None:
            self.start()
        assert self.proc is not None and self.proc.stdin is not None
        try:
            self.proc.stdin.write((json.dumps(request) + "\n").encode())
            self.proc.stdin.flush()
            answer = self._read(timeout)
        except BrokenPipeError:
            answer = "died"
        if isinstance(answer, dict):
            if answer.get("exception") == "MemoryError":
                self.stop()  # the worker exits after a MemoryError; the next case starts a fresh one
                self.restarts += 1
            return answer
        if answer == "died":
            self.proc.wait()
            code = self.proc.returncode
            self.stop()
            self.restarts += 1
            name = signal.Signals(-code).name if code is not None and code < 0 else f"exit status {code}"
            return {"rc": None, "died": name, "exception": None, "message": "", "where": "",
                    "stderr": f"the worker died ({name})"}
        where = self._stack()
        self.stop()
        self.restarts += 1
        return {"rc": None, "timeout": True, "exception": None, "message": "", "where": where,
                "stderr": f"no answer within {timeout:g} s (killed); it was at {where or 'an unknown place'}"}


def classify(result: dict[str, Any]) -> str:
    """The outcome of a case from what the worker answered (one of :data:`OUTCOMES`)."""
    if result.get("timeout"):
        return "hang"
    if result.get("died"):
        return "memory" if result["died"] == "SIGKILL" else "traceback"  # the parent kills only on a timeout
    if result.get("exception") == "MemoryError":
        return "memory"
    if result.get("exception"):
        return "traceback"
    lines = result.get("stderr", "").splitlines()
    if result.get("rc") == 0:
        return "ok"
    errors = [line for line in lines if line.startswith("likeme: error: ")]
    if result.get("rc") == 1 and len(errors) == 1 and not any(line.startswith("Traceback") for line in lines):
        return "documented"
    return "traceback"


if __name__ == "__main__" and len(sys.argv) >= 3 and sys.argv[1] == "--worker":
    _worker_main(int(sys.argv[2]), json.loads(sys.argv[3]) if len(sys.argv) > 3 else [],
                 sys.argv[4] if len(sys.argv) > 4 else "")
