"""The skysweep command line and its option tables (`skysweep COMMAND
--help-json`), from which the algorithms are made."""
import json
import os
import shutil
import subprocess

#: The commands that become algorithms, and their Processing groups.
ALGORITHMS = {"svf": "Terrain", "openness": "Terrain", "horizon": "Terrain",
              "hillshade": "Terrain", "shadow": "Sun", "insolation": "Sun"}


def command_line(configured=None):
    """(path, problem): the program named in the provider's setting, else
    SKYSWEEP_CLI, else skysweep on PATH (make install puts it there). path is
    None, and problem says why in one line, where none of them runs."""
    candidates = [("the Processing setting 'skysweep command line'", configured),
                  ("SKYSWEEP_CLI", os.environ.get("SKYSWEEP_CLI"))]
    for source, candidate in candidates:
        if candidate:
            if os.path.isfile(candidate) and os.access(candidate, os.X_OK):
                return candidate, None
            return None, (f"the skysweep command line named by {source} ({candidate}) "
                          "is not an executable file")
    found = shutil.which("skysweep")
    if found:
        return found, None
    return None, ("the skysweep command line was not found: install skysweep (make install "
                  "puts it on PATH), or name it in Processing > Options > Providers > "
                  "skysweep, or in SKYSWEEP_CLI")


def option_tables(cli):
    """({command: table} for the commands in ALGORITHMS that the CLI has,
    problem or None)."""
    tables, failed = {}, []
    for command in ALGORITHMS:
        try:
            run = subprocess.run([cli, command, "--help-json"], capture_output=True, text=True,
                                 stdin=subprocess.DEVNULL, timeout=60)
        except (OSError, subprocess.TimeoutExpired) as e:
            return {}, f"{cli} could not be run: {e}"
        if run.returncode == 0 and run.stdout.startswith("{"):
            tables[command] = json.loads(run.stdout)
        else:
            failed.append(command)
    problem = None
    if failed:
        problem = (f"{cli} gave no option table for {', '.join(failed)} "
                   "(is it skysweep, and of this plugin's version?)")
    return tables, problem
