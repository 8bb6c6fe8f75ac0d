"""The library, its declarations and the command line's option tables, as the
package was built with them (setup.py generates the three files)."""
import json
import os
import pathlib

from cffi import FFI

_HERE = pathlib.Path(__file__).resolve().parent

BUILD = json.loads((_HERE / "_options.json").read_text())

ffi = FFI()
ffi.cdef((_HERE / "_cdef.h").read_text())
#: SKYSWEEP_LIBRARY overrides the package's library: its own copy, or the
#: installed one it was built against (a sanitizer build, say).
lib = ffi.dlopen(os.environ.get("SKYSWEEP_LIBRARY") or str(_HERE / BUILD["library"]))
#: The command line the package carries or was built with (None: none).
CLI = str(_HERE / BUILD["cli"]) if BUILD["cli"] else None
#: Numeric constants of the public headers (SS_NODATA, ...).
CONST = BUILD["constants"]
#: Each command's option table, as ``skysweep COMMAND --help-json`` prints it.
COMMANDS = BUILD["commands"]
#: The library's products (its registry, skysweep_products.h) by name, in its
#: order: each has its array call, its file call and its command.
PRODUCTS = {ffi.string(p.name).decode(): p
            for p in (lib.ss_product_at(i) for i in range(lib.ss_product_count()))}


def option(command, name):
    """The option table's entry for a command's option."""
    for entry in COMMANDS[command]["options"]:
        if entry["name"] == name:
            return entry
    raise KeyError(f"skysweep {command} has no option --{name}")


def default(command, name):
    """An option's default as its table gives it (a number where it is one)."""
    entry = option(command, name)
    text = entry.get("default")
    if text is None:
        return None
    if entry["type"] == "int":
        return int(text)
    if entry["type"] == "double":
        return float(text)
    return text
