"""The package's `skysweep` command: runs the command line the package
carries (bin/skysweep), or the one it was built with, in its place."""
import os
import sys

from ._lib import CLI


def main():
    # Not PATH's skysweep: that may be this very script.
    cli = os.environ.get("SKYSWEEP_CLI") or CLI
    if not cli or not os.access(cli, os.X_OK):
        sys.exit(f"skysweep: this Python package has no command line ({cli or 'built without one'}); "
                 "set SKYSWEEP_CLI to one")
    os.execv(cli, [cli, *sys.argv[1:]])
