"""The skysweep command line and its option tables (`skysweep COMMAND
--help-json`), from which the algorithms are made."""
import json
import os
import shutil
import subprocess

#: The commands that become algorithms, and their Processing groups.
ALGORITHMS = {"svf": "Terrain", "openness": "Terrain", "horizon": "Terrain",
              "hillshade": "Terrain", "shadow": "Sun", "insolation": "Sun"}


def command_line():
    """SKYSWEEP_CLI, else skysweep on PATH (make install puts it there)."""
    for candidate in (os.environ.get("SKYSWEEP_CLI"), shutil.which("skysweep")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    return None


def option_tables(cli):
    """{command: table} for the commands in ALGORITHMS that the CLI has."""
    tables = {}
    for command in ALGORITHMS:
        run = subprocess.run([cli, command, "--help-json"], capture_output=True, text=True,
                             stdin=subprocess.DEVNULL)
        if run.returncode == 0 and run.stdout.startswith("{"):
            tables[command] = json.loads(run.stdout)
    return tables
