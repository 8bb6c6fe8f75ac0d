"""Contexts, errors, progress and cancellation around library calls.

Every call runs with the GIL released (cffi releases it around C calls). Called
from the main thread, a call runs in a worker thread while the main thread
waits, so that Ctrl-C reaches Python: it cancels the library call (the library
stops within about two directions' sweeps) and raises KeyboardInterrupt once the
call has ended (a SIGINT handler of the caller's own is called instead).
"""
import os
import signal
import sys
import threading

from ._lib import ffi, lib


class SkysweepError(Exception):
    """A library or command-line failure: ``status`` is the library's status
    code (the CLI's exit code, doc/cli.md) and the text its one-line message."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class ArgumentError(SkysweepError, ValueError):
    """An option or parameter is out of range (status 2)."""


class InputError(SkysweepError, ValueError):
    """The input cannot be read or is not a usable DEM (status 3)."""


class OutputError(SkysweepError, OSError):
    """An output cannot be written (status 4)."""


class DeviceError(SkysweepError, RuntimeError):
    """No usable OpenCL device, or the kernels failed to build (status 5)."""


class OutOfMemory(SkysweepError, MemoryError):
    """An allocation failed or would exceed a limit (status 6)."""


class Cancelled(SkysweepError):
    """The progress callback asked the run to stop (status 7)."""


class InternalError(SkysweepError, RuntimeError):
    """A bug in skysweep: please report it (status 8)."""


_ERRORS = {2: ArgumentError, 3: InputError, 4: OutputError, 5: DeviceError, 6: OutOfMemory,
           7: Cancelled, 8: InternalError}


def error_for(status, message):
    return _ERRORS.get(status, SkysweepError)(message, status)


class Context:
    """One library context (ss_ctx) on one device, as the CLI's --device
    names it: None is SKYSWEEP_DEVICE where set, else "auto" (each call's
    plan picks the fastest device for the job, doc/devices.md); "reference"
    is the C twin. A context serves one call at a time; the module's
    functions keep one per thread and device."""

    def __init__(self, device=None):
        ctx = lib.ss_ctx_new()
        if ctx == ffi.NULL:
            raise MemoryError("cannot create a skysweep context")
        self._ctx = ffi.gc(ctx, lib.ss_ctx_free)
        self.device = device
        spec = device or (None if os.environ.get("SKYSWEEP_DEVICE") else "auto")
        self.check(lib.ss_ctx_use_device(self._ctx, spec.encode() if spec else ffi.NULL))

    @property
    def ptr(self):
        return self._ctx

    def message(self):
        return ffi.string(lib.ss_ctx_message(self._ctx)).decode(errors="replace")

    def check(self, status):
        if status != 0:
            raise error_for(status, self.message())

    def fail(self, status, message):
        """Raises a failure of the front end's own, like the library's."""
        raise error_for(status, message)

    def device_name(self):
        return ffi.string(lib.ss_ctx_device_name(self._ctx)).decode(errors="replace")

    def call(self, function, *args, progress=None):
        """function(ctx, *args), a library call returning a status, with
        progress reported to `progress` (see progress_callback) and Ctrl-C
        turned into cancellation."""
        report = progress_callback(progress)
        raised = []

        @ffi.callback("int(double, const char *, void *)", onerror=lambda *e: raised.append(e))
        def on_progress(complete, message, user):
            if report is None:
                return 1
            text = ffi.string(message).decode(errors="replace") if message != ffi.NULL else ""
            return 0 if report(complete, text) is False else 1

        lib.ss_ctx_set_progress(self._ctx, on_progress if report else ffi.NULL, ffi.NULL)
        try:
            status = self._run(function, args)
        finally:
            lib.ss_ctx_set_progress(self._ctx, ffi.NULL, ffi.NULL)
            if report is not None and hasattr(report, "close"):
                report.close()
        if raised:
            raise raised[0][1].with_traceback(raised[0][2])
        self.check(status)

    def _run(self, function, args):
        previous = signal.getsignal(signal.SIGINT)
        if threading.current_thread() is not threading.main_thread() or previous in (
                signal.SIG_IGN, signal.SIG_DFL, None):
            return function(self._ctx, *args)
        result = []
        done = threading.Event()
        caught = []

        def work():
            try:
                result.append(function(self._ctx, *args))
            finally:
                done.set()

        def on_interrupt(signum, frame):
            caught.append((signum, frame))
            lib.ss_ctx_cancel(self._ctx)  # the call ends soon; wait for it

        # While the call runs, Ctrl-C cancels it instead of raising: raised
        # anywhere here (while the worker starts, say), KeyboardInterrupt
        # would leave the call running behind the caller's back.
        signal.signal(signal.SIGINT, on_interrupt)
        try:
            threading.Thread(target=work, name="skysweep", daemon=True).start()
            while not done.wait(0.05):
                pass
        finally:
            signal.signal(signal.SIGINT, previous)
        if caught:
            lib.ss_ctx_cancel_clear(self._ctx)
            if previous is signal.default_int_handler:
                raise KeyboardInterrupt
            previous(*caught[0])
        return result[0]


class _TextProgress:
    """GDAL-style 0...10...20 on stderr, for progress=True without tqdm."""

    def __init__(self):
        self.shown = -1

    def __call__(self, complete, message):
        tenth = int(complete * 40 + 1e-9)
        while self.shown < tenth:
            self.shown += 1
            sys.stderr.write(f"{self.shown // 4 * 10}" if self.shown % 4 == 0 else ".")
        if complete >= 1:
            sys.stderr.write(" - done.\n")
            self.shown = 41
        sys.stderr.flush()


class _TqdmProgress:
    def __init__(self, tqdm):
        self.bar = tqdm(total=1.0, unit="", bar_format="{l_bar}{bar}| {elapsed}<{remaining}")
        self.done = 0.0

    def __call__(self, complete, message):
        if message:
            self.bar.set_description(message, refresh=False)
        self.bar.update(max(0.0, complete - self.done))
        self.done = max(self.done, complete)

    def close(self):
        self.bar.close()


def progress_callback(progress):
    """progress None or False: none; True: a tqdm bar where tqdm is
    installed, else GDAL-style text on stderr; a callable: called as
    progress(fraction 0..1, message), and returning False cancels the run
    (Cancelled is raised)."""
    if progress is None or progress is False:
        return None
    if progress is True:
        try:
            from tqdm import tqdm
        except ImportError:
            return _TextProgress()
        return _TqdmProgress(tqdm)
    if not callable(progress):
        raise TypeError("progress must be None, True or a callable(fraction, message)")
    return progress


_local = threading.local()


def context(device=None):
    """This thread's context for a device (made on first use, then kept:
    an OpenCL device is set up once per process, not per call)."""
    if isinstance(device, Context):
        return device
    contexts = getattr(_local, "contexts", None)
    if contexts is None:
        contexts = _local.contexts = {}
    if device not in contexts:
        contexts[device] = Context(device)
    return contexts[device]
