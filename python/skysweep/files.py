"""File calls: the command line itself, run on files, so that outputs keep
their georeferencing, metadata and band names exactly as `skysweep COMMAND`
writes them. Each function's keyword arguments are its command's options
(``svf_tolerance`` for ``--svf-tolerance``), taken from the command's option
table and checked against it before the run."""
import datetime
import inspect
import os
import re
import shutil
import signal
import subprocess
import threading

import numpy as np

from ._context import error_for, progress_callback
from ._lib import CLI, COMMANDS, PRODUCTS, default
from .products import _checked
from .sun import iso_duration

#: What the file calls may not set: the package runs the command quietly
#: and reports progress itself.
_RESERVED = {"q", "help"}


def _text(key, value):
    """An option's value as the command line reads it: a path as its text,
    a datetime in ISO 8601 with its zone (the command line requires one, and
    a naive datetime is refused here as it is there), a duration (timedelta,
    pandas.Timedelta, numpy timedelta64) in ISO 8601."""
    if isinstance(value, (datetime.timedelta, np.timedelta64)):
        return iso_duration(value, key)
    if isinstance(value, datetime.datetime):
        if value.tzinfo is None or value.utcoffset() is None:
            raise ValueError(f"{key}: the datetime {value.isoformat()} has no time zone; give "
                             "an aware one (tzinfo=datetime.timezone.utc, say)")
        return value.isoformat()
    return os.fspath(value) if isinstance(value, os.PathLike) else str(value)


def command_line():
    """The skysweep executable: SKYSWEEP_CLI, else the one the package was
    built with, else the first on PATH."""
    for candidate in (os.environ.get("SKYSWEEP_CLI"), CLI, shutil.which("skysweep")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    raise FileNotFoundError("no skysweep command line found (set SKYSWEEP_CLI)")


def _arguments(command, options):
    table = {o["name"]: o for o in COMMANDS[command]["options"]}
    args = []
    for key, value in options.items():
        name = key.replace("_", "-")
        entry = table.get(name)
        if entry is None or name in _RESERVED:
            known = ", ".join(sorted(n.replace("-", "_") for n in table if n not in _RESERVED))
            raise TypeError(f"{command}_file() got an unexpected option {key!r} "
                            f"(skysweep {command} takes: {known})")
        flag = entry["dash"] + name
        if value is None or value is False:
            continue
        if entry["type"] == "flag":
            if value is not True:
                raise TypeError(f"{key} is a flag: True or False, not {value!r}")
            args.append(flag)
        elif entry["type"] == "list":
            items = ([f"{k}={v}" for k, v in value.items()] if isinstance(value, dict)
                     else [value] if isinstance(value, (str, os.PathLike)) else list(value))
            for item in items:
                args += [flag, _text(key, item)]
        else:
            if isinstance(value, bool):
                raise TypeError(f"{key} takes a value, not {value!r}")
            if entry["type"] in ("int", "double", "choice"):
                value = _checked(command, key, value)  # 16.0 for an int option becomes 16
            elif isinstance(value, (list, tuple)):
                value = ",".join(str(v) for v in value)  # -projwin (ULX, ULY, LRX, LRY)
            args += [flag, _text(key, value)]
    return args


_PROGRESS_MARK = re.compile(r"(?<![\d.])(\d{1,3})(?:\.\.\.| - done)")


class _Reader:
    """Reads one of the command's streams to its end. GDAL-style 0...10...20
    marks (GDAL prints them on stdout, among the plan and the summary) go to
    report, rising only."""

    def __init__(self, stream, report, shown):
        self.text = []
        self.thread = threading.Thread(target=self._read, args=(stream, report, shown),
                                       daemon=True)
        self.thread.start()

    def _read(self, stream, report, shown):
        pending = ""
        while True:
            chunk = stream.read1(256)
            if not chunk:
                break
            text = chunk.decode(errors="replace")
            self.text.append(text)
            if report is None:
                continue
            pending += text
            for m in _PROGRESS_MARK.finditer(pending):
                percent = int(m.group(1))
                if percent % 10 == 0 and percent > shown[0]:
                    shown[0] = percent
                    report(percent / 100.0, "")
            pending = pending[-8:]

    def result(self):
        self.thread.join()
        return "".join(self.text)


def run(command, *positional, progress=None, **options):
    """Runs `skysweep COMMAND [options] POSITIONAL...` and returns what it printed.

    Parameters
    ----------
    command : str
        A skysweep command (svf, info, sun, weather, ...).
    *positional : str or os.PathLike
        Its positional arguments (input and output paths).
    progress : bool or callable, default None
        None, True (tqdm or text) or callable(fraction, message). With progress the
        command runs without -q: its progress (shown once a run has lasted a second)
        goes to the callback, and its plan and summary are returned.
    **options
        The command's options, `-` written `_` (``svf_tolerance=0.01``): flags take
        True, lists a list or dict, datetimes and timedeltas are written in ISO 8601.

    Returns
    -------
    str
        What the command printed on stdout.

    Raises
    ------
    ValueError
        An unknown command.
    TypeError
        An option the command does not have, or a value of the wrong kind.
    SkysweepError
        The command's failure, of the class of its exit status (ArgumentError,
        InputError, OutputError, ...), carrying its one-line message.
    KeyboardInterrupt
        Ctrl-C, which stops the command within a second.
    """
    if command not in COMMANDS:
        raise ValueError(f"unknown command {command!r} (skysweep has: {', '.join(COMMANDS)})")
    args = [command_line(), command] + _arguments(command, options)
    report = progress_callback(progress)
    if report is None and any(o["name"] == "q" for o in COMMANDS[command]["options"]):
        args.append("-q")  # info, sun and weather have no progress to quieten
    args += [os.fspath(p) for p in positional]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL)
    shown = [-1]
    rc = None
    out, err = _Reader(proc.stdout, report, shown), _Reader(proc.stderr, None, shown)
    try:
        rc = proc.wait()
    except KeyboardInterrupt:
        proc.send_signal(signal.SIGINT)
        proc.wait()
        raise
    finally:
        stdout, stderr = out.result(), err.result()
        # The command's last mark may be short of 100 (it prints none after
        # its final step): the run is complete, and the bar says so before
        # it closes.
        if rc == 0 and report is not None and shown[0] < 100:
            report(1.0, "")
        if report is not None and hasattr(report, "close"):
            report.close()
    if rc != 0:
        if rc in (130, -signal.SIGINT):
            raise KeyboardInterrupt
        lines = [line for line in stderr.splitlines() if line.strip()]
        message = lines[-1] if lines else f"skysweep {command} failed with exit status {rc}"
        message = re.sub(rf"^skysweep {command}: ", "", message)
        raise error_for(rc, message)
    return stdout


def _file_call(command):
    table = COMMANDS[command]

    def call(input, output, *, progress=None, **options):
        inputs = [input] if isinstance(input, (str, os.PathLike)) else list(input)
        run(command, *inputs, output, progress=progress, **options)
        return output

    call.__name__ = call.__qualname__ = f"{command}_file"
    lines = [f"Runs `{table['usage']}` and returns output.", "", table["summary"], "",
             "Parameters", "----------",
             "input : str, os.PathLike or list of them",
             "    The DEM (a list of tiles: a mosaic).",
             "output : str or os.PathLike", "    The raster to write."]
    for o in table["options"]:
        if o["name"] in _RESERVED:
            continue
        what = ("{" + ", ".join(f'"{c}"' for c in o["choices"]) + "}" if o["type"] == "choice"
                else o.get("metavar", o["type"]))
        shown = f", default {o['default']}" if "default" in o else ", optional"
        lines += [f"{o['name'].replace('-', '_')} : {what}{shown}", f"    {o['help']}"]
    lines += ["progress : bool or callable, default None",
              "    None, True (tqdm or text) or callable(fraction, message).", "",
              "Returns", "-------", "str or os.PathLike", "    output, as given.", "",
              "Raises", "------", "TypeError",
              "    An option the command does not have, or a value of the wrong kind.",
              "SkysweepError",
              "    The command's failure, of the class of its exit status (ArgumentError,",
              "    InputError, ...), carrying its one-line message."]
    call.__doc__ = "\n".join(lines)
    # The options in the signature, with their table's defaults (help, inspect).
    keyword = inspect.Parameter.KEYWORD_ONLY
    options = [inspect.Parameter(o["name"].replace("-", "_"), keyword,
                                 default=False if o["type"] == "flag" else
                                 default(command, o["name"]))
               for o in table["options"] if o["name"] not in _RESERVED]
    call.__signature__ = inspect.Signature(
        [inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD) for n in ("input", "output")]
        + options + [inspect.Parameter("progress", keyword, default=None)])
    return call


#: The commands that turn a DEM into a raster: the library's products
#: (its registry) and the pictures.
FILE_COMMANDS = tuple(c for c in (*PRODUCTS, "render", "quicklook") if c in COMMANDS)
FILE_CALLS = {f"{c}_file": _file_call(c) for c in FILE_COMMANDS}
