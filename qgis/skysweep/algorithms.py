"""One Processing algorithm per skysweep command, made from the command's
option table: each option becomes a parameter of its type, range, default and
help. The algorithm runs the command line, so that its outputs are the CLI's
(georeferencing, band names, metadata); progress goes to the feedback and
cancelling stops the run, which then leaves no output behind."""
import os
import pathlib
import queue
import re
import signal
import sqlite3
import subprocess
import threading
import time

from qgis.core import (QgsProcessing, QgsProcessingAlgorithm, QgsProcessingContext,
                       QgsProcessingException, QgsProcessingParameterBoolean,
                       QgsProcessingParameterDefinition, QgsProcessingParameterEnum,
                       QgsProcessingParameterFeatureSource, QgsProcessingParameterFile,
                       QgsProcessingParameterFileDestination, QgsProcessingParameterNumber,
                       QgsProcessingParameterRasterDestination,
                       QgsProcessingParameterRasterLayer, QgsProcessingParameterString,
                       QgsProcessingParameterVectorDestination)

#: Options that are not parameters: the provider writes GeoTIFF and reports
#: progress itself; scenes, plans only and heightmaps belong to the CLI, and
#: so does the rule for overlapping tiles (a layer is one DEM).
NOT_PARAMETERS = {"q", "of", "scene", "plan", "plan-format", "heightmap", "z-scale", "overlap"}
#: horizon's site profiles print tables, not rasters: the CLI's --point mode.
NOT_PARAMETERS_OF = {"horizon": {"point", "points", "point-crs", "format", "step", "height",
                                 "far"}}


def parameter_name(option):
    return option.replace("-", "_").upper()


def output_named(table, entry):
    """The output an option names the file of (its entry in the table's
    "outputs", which the library's product registry declares), or None."""
    return next((o for o in table["outputs"] if o.get("option") == entry["name"]), None)


def writes_vector(table):
    """Whether the command's output (its table's output named by no option)
    is a vector file ("kind": "vector": roofs' GeoPackage), not a raster."""
    main = next(o for o in table["outputs"] if "option" not in o)
    return main.get("kind") == "vector"


def reads_vector(table, entry):
    """Whether an option names a vector file the command reads (the table's
    "vector_inputs": roofs' --buildings)."""
    return entry["name"] in table.get("vector_inputs", ())


def geopackage_layers(path):
    """The feature tables of a GeoPackage, in its gpkg_contents' order."""
    uri = pathlib.Path(path).resolve().as_uri() + "?mode=ro"  # a path with spaces, ? or #
    with sqlite3.connect(uri, uri=True) as db:
        return [row[0] for row in db.execute("SELECT table_name FROM gpkg_contents WHERE "
                                             "data_type = 'features' ORDER BY rowid")]


def is_advanced(entry):
    """An option the CLI groups with the advanced ones (`"group": "advanced"`
    in --help-json; its --help lists them last): shown under "Advanced
    parameters"."""
    return entry.get("group") == "advanced"


def parameters_of(table):
    """The table's options that become parameters."""
    skip = NOT_PARAMETERS | NOT_PARAMETERS_OF.get(table["command"], set())
    return [o for o in table["options"] if o["name"] not in skip]


def _description(entry):
    """"Svf tolerance [SVF]": the option in words, with its unit; the whole
    help is the parameter's help and in the algorithm's."""
    label = entry["name"].replace("-", " ").capitalize()
    unit = entry.get("metavar")
    if unit and entry["type"] in ("int", "double") and unit not in ("N", "K"):
        label += f" [{unit}]"
    return label


def choice_name(choices, value):
    """The choice a value names: the choice itself (DEFINITION=radiative) or
    its index, as Processing's dialogs and scripts give it (DEFINITION=1)."""
    text = str(value).strip()
    if text in choices:
        return text
    if text.isdigit() and int(text) < len(choices):
        return choices[int(text)]
    raise QgsProcessingException(f"{text!r} is not one of {', '.join(choices)} "
                                 f"(or their index, 0 to {len(choices) - 1})")


class ChoiceParameter(QgsProcessingParameterEnum):
    """An Enum whose value is the choice's name, as on the command line, and
    which also takes the choice's index: Processing's static-string Enum
    refuses an index headless and turns it into the default in
    parameterAsEnumString."""

    def __init__(self, name, label, choices, default):
        super().__init__(name, label, choices, False, default, False, True)

    def clone(self):
        copy = ChoiceParameter(self.name(), self.description(), self.options(),
                               self.defaultValue())
        copy.setFlags(self.flags())
        copy.setHelp(self.help())
        return copy

    def checkValueIsAcceptable(self, value, context=None):
        if value is None or value == "":
            return self.defaultValue() is not None
        try:
            choice_name(self.options(), value)
        except QgsProcessingException:
            return False
        return True


class SkysweepAlgorithm(QgsProcessingAlgorithm):
    def __init__(self, cli, table):
        super().__init__()
        self.cli = cli
        self.table = table

    def createInstance(self):
        return SkysweepAlgorithm(self.cli, self.table)

    def name(self):
        return self.table["command"]

    def displayName(self):
        return self.table["title"]

    def group(self):
        return self.table["group"]

    def groupId(self):
        return self.table["group"].lower()

    def shortHelpString(self):
        lines = [self.table["summary"].replace("\n", " "), "", f"Runs: {self.table['usage']}", ""]
        for entry in parameters_of(self.table):
            what = "|".join(entry["choices"]) if entry["type"] == "choice" else \
                entry.get("metavar", entry["type"])
            default = f" (default {entry['default']})" if "default" in entry else ""
            lines.append(f"{parameter_name(entry['name'])} ({what}){default}: {entry['help']}")
        return "\n".join(lines)

    def initAlgorithm(self, config=None):
        self.addParameter(QgsProcessingParameterRasterLayer("INPUT", "DEM (heights)"))
        for entry in parameters_of(self.table):
            parameter = self._parameter(entry)
            parameter.setHelp(entry["help"])
            if is_advanced(entry):
                parameter.setFlags(parameter.flags()
                                   | QgsProcessingParameterDefinition.FlagAdvanced)
            self.addParameter(parameter)
        if writes_vector(self.table):
            self.addParameter(QgsProcessingParameterVectorDestination(
                "OUTPUT", self.displayName(), QgsProcessing.TypeVectorAnyGeometry))
        else:
            self.addParameter(QgsProcessingParameterRasterDestination("OUTPUT",
                                                                      self.displayName()))

    def _parameter(self, entry):
        name, label = parameter_name(entry["name"]), _description(entry)
        default = entry.get("default")
        kind = entry["type"]
        if kind in ("int", "double"):
            number = QgsProcessingParameterNumber.Integer if kind == "int" else \
                QgsProcessingParameterNumber.Double
            value = None if default is None else (int(default) if kind == "int"
                                                  else float(default))
            return QgsProcessingParameterNumber(name, label, number, value, default is None,
                                                entry["min"], entry["max"])
        if kind == "choice":
            return ChoiceParameter(name, label, entry["choices"], default)
        if kind == "flag":
            return QgsProcessingParameterBoolean(name, label, False)
        if output_named(self.table, entry):
            return QgsProcessingParameterRasterDestination(name, label, None, True, False)
        if entry.get("output", False):  # a table beside the output (roofs' --csv)
            return QgsProcessingParameterFileDestination(name, label, "All files (*)", None,
                                                         True, False)
        if reads_vector(self.table, entry):
            return QgsProcessingParameterFeatureSource(name, label, [QgsProcessing.TypeVector],
                                                       None, True)
        if entry.get("input", False):
            return QgsProcessingParameterFile(name, label, optional=True)
        return QgsProcessingParameterString(name, label, default, False, default is None)

    def command(self, parameters, context, feedback=None):
        """The command line for these parameter values."""
        args = [self.cli, self.name()]
        for entry in parameters_of(self.table):
            name = parameter_name(entry["name"])
            flag = entry["dash"] + entry["name"]
            if parameters.get(name) is None:
                continue
            kind = entry["type"]
            if kind == "int":
                args += [flag, str(self.parameterAsInt(parameters, name, context))]
            elif kind == "double":
                args += [flag, repr(self.parameterAsDouble(parameters, name, context))]
            elif kind == "choice":
                args += [flag, choice_name(entry["choices"], parameters[name])]
            elif kind == "flag":
                if self.parameterAsBoolean(parameters, name, context):
                    args.append(flag)
            elif output_named(self.table, entry):
                path = self.parameterAsOutputLayer(parameters, name, context)
                if path:
                    args += [flag, path]
            elif entry.get("output", False):
                path = self.parameterAsFileOutput(parameters, name, context)
                if path:
                    args += [flag, path]
            elif reads_vector(self.table, entry):
                # The CLI reads a file's first layer: a layer that is not one
                # (a GeoPackage's second, a memory layer, a selection, a
                # filter) goes to a temporary GeoPackage first.
                args += [flag, self.parameterAsCompatibleSourceLayerPath(
                    parameters, name, context, ["gpkg", "shp", "geojson"], "gpkg", feedback)]
            else:
                text = self.parameterAsString(parameters, name, context)
                if kind == "list":
                    for item in text.split():
                        args += [flag, item]
                elif text:
                    args += [flag, text]
        layer = self.parameterAsRasterLayer(parameters, "INPUT", context)
        if layer is None:
            raise QgsProcessingException("INPUT is not a raster layer QGIS can open")
        args.append(layer.source())
        args.append(self.parameterAsOutputLayer(parameters, "OUTPUT", context))
        return args

    def processAlgorithm(self, parameters, context, feedback):
        args = self.command(parameters, context, feedback)
        feedback.pushCommandInfo(" ".join(args))
        environment = dict(os.environ, SKYSWEEP_PROGRESS="lines")
        with subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              stdin=subprocess.DEVNULL, env=environment) as proc:
            cancelled, errors = self._follow(proc, feedback)
        lines = [line for line in "".join(errors).splitlines() if line.strip()]
        if proc.returncode != 0 and (cancelled or feedback.isCanceled()):
            feedback.reportError("cancelled: no output written")
            return {}
        if proc.returncode != 0:
            raise QgsProcessingException(lines[-1] if lines else
                                         f"skysweep {self.name()} failed ({proc.returncode})")
        for line in lines:  # the CLI's warnings (e.g. heights taken as nodata)
            feedback.pushWarning(line)
        outputs = {"OUTPUT": self.parameterAsOutputLayer(parameters, "OUTPUT", context)}
        for entry in parameters_of(self.table):
            name = parameter_name(entry["name"])
            if output_named(self.table, entry) and parameters.get(name):
                outputs[name] = self.parameterAsOutputLayer(parameters, name, context)
            elif entry.get("output", False) and parameters.get(name):
                outputs[name] = self.parameterAsFileOutput(parameters, name, context)
        if writes_vector(self.table):
            self._load_every_layer(outputs["OUTPUT"], context)
        return outputs

    @staticmethod
    def _load_every_layer(path, context):
        """Where the run loads its output (the desktop's dialog), each layer
        of the GeoPackage under its own name (buildings, roof_planes), in
        place of the file, which would load as its first layer alone."""
        if not context.willLoadLayerOnCompletion(path):
            return
        layers = context.layersToLoadOnCompletion()
        details = layers.pop(path)
        for layer in geopackage_layers(path):
            layers[f"{path}|layername={layer}"] = QgsProcessingContext.LayerDetails(
                layer, details.project, details.outputName)
        context.setLayersToLoadOnCompletion(layers)

    @staticmethod
    def _follow(proc, feedback):
        """Relays the run's progress and log until it ends; Ctrl-C (SIGINT)
        when the user cancels. Returns (cancelled, stderr chunks)."""
        chunks = queue.Queue()
        readers = [threading.Thread(target=_read, args=(stream, kind, chunks), daemon=True)
                   for stream, kind in ((proc.stdout, "out"), (proc.stderr, "err"))]
        for r in readers:
            r.start()
        progress = _Progress(feedback)
        errors = []
        cancelled = None  # when SIGINT was sent
        while proc.poll() is None or not chunks.empty() or any(r.is_alive() for r in readers):
            if feedback.isCanceled() and cancelled is None and proc.poll() is None:
                proc.send_signal(signal.SIGINT)  # the CLI stops within a second, output removed
                cancelled = time.monotonic()
            elif cancelled is not None and proc.poll() is None and time.monotonic() - cancelled > 10:
                proc.terminate()  # SIGTERM: the CLI removes its output on it too
            try:
                kind, text = chunks.get(timeout=0.1)
            except queue.Empty:
                continue
            if kind == "out":
                progress.feed(text)
            else:
                errors.append(text)
        progress.flush()
        return cancelled is not None, errors


def _read(stream, kind, chunks):
    while True:
        data = stream.read1(256)
        if not data:
            break
        chunks.put((kind, data.decode(errors="replace")))


class _Progress:
    """Splits the CLI's stdout, run with SKYSWEEP_PROGRESS=lines, into its
    progress lines ("progress 0.1234", one per direction or step, to the
    progress bar) and the lines of its plan and summary (to the log)."""

    LINE = re.compile(r"progress ([0-9.]+)$")

    def __init__(self, feedback):
        self.feedback = feedback
        self.text = ""

    def feed(self, text):
        self.text += text
        *lines, self.text = self.text.split("\n")
        for line in lines:
            mark = self.LINE.match(line)
            if mark:
                self.feedback.setProgress(min(100.0, 100.0 * float(mark.group(1))))
            else:
                self.feedback.pushInfo(line)

    def flush(self):
        if self.text.strip():
            self.feed("\n")
