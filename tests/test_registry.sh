#!/bin/bash
# Every product of the library's registry (skysweep_products.h, listed by
# tests/test_registry --list) has each face the front ends derive from it:
# its CLI command, its --help-json "outputs" (the registry's, each
# "output": true, an optional one naming a file option marked as an
# output), its Python array call, its QGIS algorithm (the provider's own
# reading of the CLI, qgis/skysweep/cli.py, run without QGIS) and its man
# page; and every command, plan and run included, has a man page.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
SKYSWEEP=$(realpath "${SKYSWEEP:-./skysweep}")
build=$(dirname "$SKYSWEEP")
registry=${REGISTRY:-$build/tests/test_registry}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-registry.XXXXXX")
trap 'rm -rf "$work"' EXIT

"$registry" --list >"$work/registry" 2>&1
tap_ok $? "the registry lists $(wc -l <"$work/registry") products: $(cut -d' ' -f1 "$work/registry" | tr '\n' ' ')"
commands=" $("$SKYSWEEP" --help-commands) "

# The QGIS provider's algorithms, as its loader finds them (cli.option_tables).
PYTHONPATH=$top/qgis/skysweep python3 -c '
import sys, cli
tables, problem = cli.option_tables(sys.argv[1])
for name, t in tables.items():
    print(name, t["title"].replace(" ", "_"), t["group"])
' "$SKYSWEEP" >"$work/qgis" 2>&1
tap_ok $? "the QGIS provider's loader reads the CLI: $(cut -d' ' -f1 "$work/qgis" | tr '\n' ' ')"

# The package's public calls (__all__ of python/skysweep/__init__.py), read
# without importing it (that needs a built package: tests/test_python.sh).
python3 -c '
import ast, sys
tree = ast.parse(open(sys.argv[1]).read())
for node in tree.body:
    if isinstance(node, ast.Assign) and node.targets[0].id == "__all__":
        value = node.value.left if isinstance(node.value, ast.BinOp) else node.value
        print(" ".join(ast.literal_eval(value)))
' "$top/python/skysweep/__init__.py" >"$work/python" 2>&1
python_calls=" $(cat "$work/python") "

while read -r name outputs; do
    case $commands in *" $name "*) in_list=0 ;; *) in_list=1 ;; esac
    "$SKYSWEEP" "$name" --help >/dev/null 2>&1
    help=$?
    [ "$in_list" -eq 0 ] && [ "$help" -eq 0 ]
    tap_ok $? "$name: a CLI command (in --help-commands: $([ "$in_list" -eq 0 ] && echo yes || echo no), --help exit $help)"

    "$SKYSWEEP" "$name" --help-json >"$work/$name.json" 2>/dev/null
    got=$(python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))
files = {o["name"] for o in t["options"] if o.get("output")}
bad = [o["name"] for o in t.get("outputs", []) if o.get("output") is not True
       or ("option" in o) != o["optional"] or o.get("option", "") not in files | {""}]
print(" ".join(o["name"] for o in t.get("outputs", [])) + (" BAD:" + ",".join(bad) if bad else ""))
' "$work/$name.json" 2>&1)
    [ "$got" = "$outputs" ]
    tap_ok $? "$name: --help-json lists its outputs as the registry declares them ($got; want $outputs)"

    case $python_calls in *" $name "*) rc=0 ;; *) rc=1 ;; esac
    tap_ok $rc "$name: a Python array call, skysweep.$name (python/skysweep/__init__.py's __all__)"

    grep -q "^$name [^ ]* \(Terrain\|Sun\)$" "$work/qgis"
    tap_ok $? "$name: a QGIS algorithm, skysweep:$name ($(grep "^$name " "$work/qgis" || echo none))"

    [ -s "$build/man/skysweep-$name.1" ] && head -n 1 "$build/man/skysweep-$name.1" | grep -q '^\.TH'
    tap_ok $? "$name: a man page, skysweep-$name(1)"
done <"$work/registry"

missing=""
for c in $commands; do
    [ -s "$build/man/skysweep-$c.1" ] || missing="$missing $c"
done
tap_ok "$([ -z "$missing" ]; echo $?)" "every command has a man page${missing:+; missing:$missing}"
tap_done
