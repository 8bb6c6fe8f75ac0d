"""Every public function has a numpydoc docstring (Parameters naming each
of its parameters, Returns, Raises), real defaults in its signature, and a
mention in doc/python.md."""
import inspect
import pathlib
import re

import pytest

import skysweep
from skysweep._lib import COMMANDS, default

DOC = pathlib.Path(__file__).resolve().parents[2] / "doc" / "python.md"
FUNCTIONS = sorted(n for n in skysweep.__all__ if inspect.isfunction(getattr(skysweep, n)))
#: The command whose option table gives each array call's defaults.
COMMAND_OF = {"svf": "svf", "openness": "openness", "horizon": "horizon", "shadow": "shadow",
              "hillshade": "hillshade", "vat": "hillshade", "plan": "svf",
              "site_horizon": "horizon", "insolation": "insolation"}
#: Former names kept as aliases (default None: not given), and units that
#: are not the table's: pvlib's pressure in Pa (not hPa), vat's radius in
#: metres (not the blend's cells).
OWN_DEFAULTS = {("hillshade", "az"), ("hillshade", "alt"), ("insolation", "linke"),
                ("insolation", "pressure"), ("vat", "blend_radius")}


def sections(doc):
    """numpydoc sections: {title: text} for each title underlined with dashes."""
    parts = re.split(r"^(\w[\w ]*)\n-{3,}\n", doc, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2]))


def test_there_are_public_functions_to_check():
    assert {"svf", "insolation", "sun_position", "run", "svf_file"} <= set(FUNCTIONS)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_numpydoc_docstring_documents_every_parameter(name):
    function = getattr(skysweep, name)
    doc = inspect.getdoc(function) or ""
    found = sections(doc)
    for title in ("Parameters", "Returns", "Raises"):
        assert found.get(title, "").strip(), f"{name}: no {title} section"
    documented = set()
    for line in found["Parameters"].splitlines():
        m = re.match(r"^(\*{0,2}[\w, *]+?) :|^(\*{1,2}\w+)$", line)
        if m:
            documented |= {n.strip().lstrip("*") for n in (m.group(1) or m.group(2)).split(",")}
    params = set(inspect.signature(function).parameters)
    assert params <= documented, f"{name}: undocumented {sorted(params - documented)}"
    assert documented <= params, f"{name}: documents no such {sorted(documented - params)}"


@pytest.mark.parametrize("name", sorted(COMMAND_OF))
def test_signatures_hold_the_tables_defaults(name):
    """No None placeholder where the command's table has a default."""
    command = COMMAND_OF[name]
    table = {o["name"].replace("-", "_") for o in COMMANDS[command]["options"]}
    for p in inspect.signature(getattr(skysweep, name)).parameters.values():
        if p.name not in table or (name, p.name) in OWN_DEFAULTS or p.default is p.empty:
            continue  # not the table's, the call's own, or required (shadow's sun)
        given = default(command, p.name.replace("_", "-"))
        if given is not None:
            assert p.default == given, (name, p.name)


def test_doc_python_md_mentions_every_public_function():
    text = DOC.read_text()
    missing = [n for n in FUNCTIONS if not re.search(rf"`{n}[`(]", text)]
    assert not missing, f"doc/python.md does not mention {missing}"
