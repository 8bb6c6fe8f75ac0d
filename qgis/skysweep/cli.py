"""The skysweep command line and its option tables (`skysweep COMMAND
--help-json`), from which the algorithms are made: one per product of the
library's registry, which is what a table with "outputs" is."""
import json
import os
import shutil
import subprocess


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


def _run(cli, *args):
    return subprocess.run([cli, *args], capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=60)


def option_tables(cli):
    """({command: table} for the products the CLI has: the commands whose
    table lists "outputs", problem or None)."""
    tables, failed = {}, []
    try:
        commands = _run(cli, "--help-commands")
        for command in commands.stdout.split() if commands.returncode == 0 else []:
            run = _run(cli, command, "--help-json")
            if run.returncode == 0 and run.stdout.startswith("{"):
                table = json.loads(run.stdout)
                if table.get("outputs"):
                    tables[command] = table
            elif command not in ("plan", "run"):  # scene verbs: no table of their own
                failed.append(command)
    except (OSError, subprocess.TimeoutExpired) as e:
        return {}, f"{cli} could not be run: {e}"
    problem = None
    if not tables or failed:
        problem = (f"{cli} gave no option table for {', '.join(failed) or 'any product'} "
                   "(is it skysweep, and of this plugin's version?)")
    return tables, problem
