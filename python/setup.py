"""Builds the package from a built skysweep source tree.

Three files are generated into the package from the tree's own build, so that
the binding cannot drift from the library or the command line:
  - libskysweep.so.0, the library itself (the package carries its own copy);
  - _cdef.h, the public headers run through the C preprocessor, which cffi reads;
  - _options.json, every command's option table (`skysweep COMMAND --help-json`)
    and the path of the command line the file calls run.
SKYSWEEP_BUILD_DIR names the built tree (default: the directory above this one).
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import tempfile

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
TREE = pathlib.Path(os.environ.get("SKYSWEEP_BUILD_DIR", HERE.parent)).resolve()
HEADERS = ["skysweep.h", "skysweep_sun.h", "skysweep_sites.h", "skysweep_params.h"]


def version():
    text = (TREE / "configure.ac").read_text()
    return re.search(r"AC_INIT\(\[skysweep\], \[([^]]+)\]", text).group(1)


def fail(message):
    raise SystemExit(f"skysweep python package: {message}")


def cdef_text():
    """The public headers as cffi reads them: preprocessed, without system
    headers (cffi knows size_t and uint64_t), attributes and line markers."""
    with tempfile.TemporaryDirectory() as fake:
        for name in ("stddef.h", "stdint.h"):
            pathlib.Path(fake, name).write_text("")
        source = "".join(f'#include "{h}"\n' for h in HEADERS)
        cc = os.environ.get("CC", "cc")
        run = subprocess.run(
            [cc, "-E", "-P", "-nostdinc", "-I", fake, "-I", str(TREE / "src"),
             "-D__attribute__(x)=", "-"],
            input=source, capture_output=True, text=True)
        if run.returncode != 0:
            fail(f"cannot preprocess the headers with {cc}: {run.stderr.strip()}")
        return run.stdout


def constants():
    """The headers' numeric #defines (SS_NODATA, ...), which the
    preprocessor consumes and cffi's ABI mode cannot read."""
    out = {}
    for h in HEADERS:
        for name, value in re.findall(r"#define (SS_[A-Z0-9_]+) \(?(-?[0-9.]+(?:e-?[0-9]+)?)f?\)?\s",
                                      (TREE / "src" / h).read_text()):
            out[name] = float(value) if re.search(r"[.e]", value) else int(value)
    return out


def option_tables(cli):
    commands = subprocess.run([cli, "--help-commands"], capture_output=True, text=True,
                              check=True).stdout.split()
    tables = {}
    for command in commands:
        run = subprocess.run([cli, command, "--help-json"], capture_output=True, text=True)
        if run.returncode == 0 and run.stdout.startswith("{"):
            tables[command] = json.loads(run.stdout)
    return tables


class BuildFromTree(build_py):
    def run(self):
        super().run()
        library = TREE / ".libs" / "libskysweep.so.0"
        cli = TREE / "skysweep"
        if not library.exists() or not cli.exists():
            fail(f"no built library in {TREE} (run build-aux/build.sh there first, or set "
                 "SKYSWEEP_BUILD_DIR to a built tree)")
        target = pathlib.Path(self.build_lib, "skysweep")
        target.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(library.resolve(), target / "libskysweep.so.0")
        (target / "_cdef.h").write_text(cdef_text())
        build = {"version": version(), "cli": str(cli), "constants": constants(),
                 "commands": option_tables(str(cli))}
        (target / "_options.json").write_text(json.dumps(build, indent=1))


setup(version=version(), cmdclass={"build_py": BuildFromTree})
