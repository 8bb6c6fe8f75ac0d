"""The QGIS provider run as QGIS runs it (PyQGIS, headless): outputs equal
the CLI's cell for cell and load as layers with their band names; progress
reaches the feedback; a cancelled run stops within seconds and leaves
nothing behind. Prints one "PASS|FAIL description" line per check.

usage: python3 check_provider.py PLUGIN_DIR WORK_DIR  (SKYSWEEP_CLI set)"""
import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
from osgeo import gdal
from qgis.core import (QgsApplication, QgsProcessingContext, QgsProcessingFeedback,
                       QgsProcessingParameterDefinition, QgsProcessingParameterFeatureSource,
                       QgsProcessingParameterFileDestination,
                       QgsProcessingParameterVectorDestination, QgsProject, QgsRasterLayer,
                       QgsVectorLayer)

plugin_dir, work = sys.argv[1], sys.argv[2]
cli = os.environ["SKYSWEEP_CLI"]
sample = os.path.join(os.path.dirname(cli), "samples", "kilauea_summit_30m.tif")

QgsApplication.setPrefixPath("/usr", True)
app = QgsApplication([], False)
app.initQgis()
sys.path.append("/usr/share/qgis/python/plugins")
from processing.core.Processing import Processing  # noqa: E402

Processing.initialize()
import processing  # noqa: E402

sys.path.insert(0, plugin_dir)
from skysweep.provider import SkysweepProvider  # noqa: E402

provider = SkysweepProvider()  # kept: the registry does not own the Python object
QgsApplication.processingRegistry().addProvider(provider)


def check(ok, description):
    print(f"{'PASS' if ok else 'FAIL'} {description}", flush=True)


def bands(path):
    ds = gdal.Open(path)
    return [ds.GetRasterBand(b + 1).ReadAsArray() for b in range(ds.RasterCount)]


class Feedback(QgsProcessingFeedback):
    def __init__(self, cancel_after=None):
        super().__init__()
        self.progress = []
        self.progressChanged.connect(self.progress.append)
        if cancel_after is not None:
            threading.Timer(cancel_after, self.cancel).start()


# Each algorithm against the CLI with the same options.
runs = [
    ("svf", {"DIRECTIONS": 16, "DEFINITION": "radiative"}, ["--directions", "16", "--definition", "radiative"]),
    ("openness", {"DIRECTIONS": 8, "KIND": "negative"}, ["--directions", "8", "--kind", "negative"]),
    ("horizon", {"DIRECTIONS": 4}, ["--directions", "4"]),
    ("hillshade", {"AZ": 100, "ALT": 30, "MULTIDIRECTIONAL": False}, ["--az", "100", "--alt", "30"]),
    ("shadow", {"TIME": "2026-06-21T18:00Z"}, ["--time", "2026-06-21T18:00Z"]),
    ("insolation", {"TIME": "2026-06-21T16:00Z/PT4H", "STEP": "PT1H", "DIRECTIONS": 8},
     ["--time", "2026-06-21T16:00Z/PT4H", "--step", "PT1H", "--directions", "8"]),
]
for name, params, cli_args in runs:
    mine = os.path.join(work, f"q_{name}.tif")
    theirs = os.path.join(work, f"c_{name}.tif")
    feedback = Feedback()
    result = processing.run(f"skysweep:{name}", dict(params, INPUT=sample, OUTPUT=mine),
                            feedback=feedback)
    subprocess.run([cli, name, "-q", *cli_args, sample, theirs], check=True)
    a, b = bands(mine), bands(theirs)
    same = len(a) == len(b) and all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b))
    check(same and result["OUTPUT"] == mine,
          f"skysweep:{name} equals `skysweep {name} {' '.join(cli_args)}` ({len(a)} bands, cell for cell)")
    layer = QgsRasterLayer(mine, name)
    ds = gdal.Open(theirs)  # held: a band outlives no dataset in GDAL's Python
    described = [ds.GetRasterBand(i + 1).GetDescription() for i in range(len(b))]
    ds = None
    names_ok = layer.isValid() and all(d and d in layer.bandName(i + 1)
                                       for i, d in enumerate(described))
    check(names_ok, f"skysweep:{name}'s output loads as a layer with its band names "
                    f"({layer.bandName(1)!r}, CRS {layer.crs().authid()})")

# Progress: a run long enough for the CLI to report it (it does after a second).
feedback = Feedback()
processing.run("skysweep:svf", {"INPUT": sample, "OUTPUT": os.path.join(work, "long.tif"),
                                "DIRECTIONS": 720, "DEVICE": "reference"}, feedback=feedback)
steps = sorted(set(feedback.progress))
check(len(steps) >= 100 and feedback.progress == sorted(feedback.progress)
      and feedback.progress[-1] == 100,
      f"progress reaches QGIS's feedback per direction, not in 10 % jumps ({len(steps)} "
      f"values: {feedback.progress[:3]}...{feedback.progress[-1:]})")

# Cancelling stops the run and leaves nothing behind.
cancel_dir = os.path.join(work, "cancel")
os.mkdir(cancel_dir)
target = os.path.join(cancel_dir, "svf.tif")
feedback = Feedback(cancel_after=1.0)
start = time.perf_counter()
result = processing.run("skysweep:svf", {"INPUT": sample, "OUTPUT": target,
                                         "DIRECTIONS": 100000, "DEVICE": "reference"},
                        feedback=feedback)
took = time.perf_counter() - start
left = os.listdir(cancel_dir)
check(took < 4 and not left and result == {},
      f"a run cancelled after 1 s stops ({took:.1f} s in all) and leaves nothing ({left})")

# A failure the CLI finds is a Processing error carrying its message; one
# that the parameters' ranges catch never reaches the CLI.
try:
    processing.run("skysweep:shadow", {"INPUT": sample, "OUTPUT": os.path.join(work, "x.tif")})
    check(False, "shadow without a sun fails")
except Exception as e:
    check("no sun: give --time" in str(e), f"shadow without a sun fails with the CLI's message: {e}")
try:
    processing.run("skysweep:svf", {"INPUT": sample, "OUTPUT": os.path.join(work, "x.tif"),
                                    "DIRECTIONS": 0})
    check(False, "DIRECTIONS=0 is refused")
except Exception as e:
    check("DIRECTIONS" in str(e), f"DIRECTIONS=0 is refused: {' '.join(str(e).split())}")
check(not os.path.exists(os.path.join(work, "x.tif")), "failed runs leave no output")
# A choice given by its index, as dialogs and scripts give it, is that choice.
by_index, by_name = os.path.join(work, "index.tif"), os.path.join(work, "name.tif")
for path, definition in ((by_index, 1), (by_name, "radiative")):
    processing.run("skysweep:svf", {"INPUT": sample, "OUTPUT": path, "DIRECTIONS": 8,
                                    "DEFINITION": definition})
check(all(np.array_equal(x, y, equal_nan=True) for x, y in zip(bands(by_index), bands(by_name))),
      "DEFINITION=1 runs the second choice, radiative, cell for cell")
try:
    processing.run("skysweep:svf", {"INPUT": sample, "OUTPUT": os.path.join(work, "x.tif"),
                                    "DEFINITION": 3})
    check(False, "DEFINITION=3 (one past the last choice) is refused")
except Exception as e:
    check("DEFINITION" in str(e), f"DEFINITION=3 is refused: {' '.join(str(e).split())}")

# roofs writes a GeoPackage of vector layers and reads footprints as a vector
# layer: one that is not its file's first layer reaches the CLI through a
# temporary GeoPackage (the CLI reads a file's first layer).
roofs = QgsApplication.processingRegistry().algorithmById("skysweep:roofs")
kinds = {p.name(): type(p) for p in roofs.parameterDefinitions()} if roofs else {}
check(kinds.get("OUTPUT") is QgsProcessingParameterVectorDestination
      and kinds.get("BUILDINGS") is QgsProcessingParameterFeatureSource
      and kinds.get("CSV") is QgsProcessingParameterFileDestination,
      f"skysweep:roofs has a vector destination, a vector input and a CSV destination "
      f"({', '.join(f'{k}: {v.__name__}' for k, v in kinds.items() if k in ('OUTPUT', 'BUILDINGS', 'CSV'))})")
city = os.path.join(work, "city")
os.mkdir(city)
subprocess.run(["sh", os.path.join(os.path.dirname(plugin_dir), "tests", "data", "make_city.sh"),
                city], check=True)
footprints = os.path.join(city, "footprints.geojson")
two_layers = os.path.join(city, "two.gpkg")
subprocess.run(["ogr2ogr", "-f", "GPKG", "-nln", "first", "-where", "building_id = 'C'",
                two_layers, footprints], check=True)
subprocess.run(["ogr2ogr", "-update", "-nln", "second", two_layers, footprints], check=True)
weather = os.path.join(os.path.dirname(cli), "samples", "weather", "pvgis_tmy_45N_8E.csv")
roof_options = ["--time", "2018-01-10T00:00Z/P1D", "--directions", "8", "--min-irradiation", "0",
                "--device", "reference"]
subprocess.run([cli, "roofs", "-q", "--buildings", footprints, "--weather", weather,
                *roof_options, os.path.join(city, "city.tif"), os.path.join(city, "cli.gpkg")],
               check=True)
expected = {layer: QgsVectorLayer(f"{os.path.join(city, 'cli.gpkg')}|layername={layer}", layer,
                                  "ogr").featureCount() for layer in ("buildings", "roof_planes")}
mine = os.path.join(city, "qgis.gpkg")
result = processing.runAndLoadResults("skysweep:roofs", {
    "INPUT": os.path.join(city, "city.tif"), "BUILDINGS": f"{two_layers}|layername=second",
    "WEATHER": weather, "TIME": "2018-01-10T00:00Z/P1D", "DIRECTIONS": 8, "MIN_IRRADIATION": 0,
    "DEVICE": "reference", "CSV": os.path.join(city, "planes.csv"), "OUTPUT": mine})
loaded = {layer: QgsProject.instance().mapLayersByName(layer) for layer in expected}
counts = {layer: [found.featureCount() for found in loaded[layer]
                  if isinstance(found, QgsVectorLayer) and found.isValid()] for layer in expected}
check(result and result["OUTPUT"] == mine and all(counts[k] == [n] for k, n in expected.items())
      and os.path.getsize(os.path.join(city, "planes.csv")) > 0,
      f"skysweep:roofs on a GeoPackage's second layer loads buildings and roof_planes as valid "
      f"vector layers with the CLI's feature counts ({counts}; the CLI's: {expected})")

# Advanced parameters are the options the CLI groups as advanced, and no others.
wrong, advanced = [], 0
for algorithm in provider.algorithms():
    table = json.loads(subprocess.run([cli, algorithm.name(), "--help-json"], check=True,
                                      capture_output=True, text=True).stdout)
    groups = {o["name"].replace("-", "_").upper(): o["group"] for o in table["options"]}
    for parameter in algorithm.parameterDefinitions():
        if parameter.name() in ("INPUT", "OUTPUT"):
            continue
        flagged = bool(parameter.flags() & QgsProcessingParameterDefinition.FlagAdvanced)
        advanced += flagged
        if flagged != (groups.get(parameter.name()) == "advanced"):
            wrong.append(f"{algorithm.name()}:{parameter.name()}")
check(not wrong and advanced >= 50,
      f"the advanced parameters are the CLI's advanced options ({advanced} in "
      f"{len(provider.algorithms())} algorithms){', not: ' + ' '.join(wrong) if wrong else ''}")

# A CLI that is not there gives a message, not an empty provider in silence;
# the provider's setting names the CLI over SKYSWEEP_CLI and PATH.
from processing.core.ProcessingConfig import ProcessingConfig  # noqa: E402
from skysweep.provider import CLI_SETTING  # noqa: E402

os.environ["SKYSWEEP_CLI"] = os.path.join(work, "no-such-skysweep")
provider.refreshAlgorithms()
check(not provider.algorithms() and "no-such-skysweep" in provider.warningMessage(),
      f"a missing CLI leaves no algorithms and says why: {provider.warningMessage()}")
ProcessingConfig.setSettingValue(CLI_SETTING, cli)
provider.refreshAlgorithms()
check(len(provider.algorithms()) == 7 and not provider.warningMessage(),
      f"the Processing setting names the CLI ({len(provider.algorithms())} algorithms)")
ProcessingConfig.setSettingValue(CLI_SETTING, "")
sys.stdout.flush()
# PyQGIS may crash in exitQgis over objects Python still holds; the checks
# are printed, so leave without it.
os._exit(0)
