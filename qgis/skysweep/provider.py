"""The Processing provider: one algorithm per command."""
from qgis.core import Qgis, QgsMessageLog, QgsProcessingProvider

from .algorithms import SkysweepAlgorithm
from .cli import command_line, option_tables

#: The provider's setting naming the skysweep program (Processing > Options >
#: Providers > skysweep); empty: SKYSWEEP_CLI, else PATH.
CLI_SETTING = "SKYSWEEP_CLI_PATH"


def _processing_config():
    """Processing's settings classes, where the Processing plugin is loaded
    (the desktop, qgis_process); None elsewhere."""
    try:
        from processing.core.ProcessingConfig import ProcessingConfig, Setting
    except ImportError:
        return None
    return ProcessingConfig, Setting


class SkysweepProvider(QgsProcessingProvider):
    def __init__(self):
        super().__init__()
        self.cli = None
        self.tables = {}
        self.problem = None

    def load(self):
        config = _processing_config()
        if config:
            ProcessingConfig, Setting = config
            ProcessingConfig.settingIcons[self.name()] = self.icon()
            ProcessingConfig.addSetting(Setting(
                self.name(), CLI_SETTING, "skysweep command line (empty: SKYSWEEP_CLI, else "
                "skysweep on PATH)", "", valuetype=Setting.FILE))
            ProcessingConfig.readSettings()
        self.refreshAlgorithms()
        return True

    def unload(self):
        config = _processing_config()
        if config:
            config[0].removeSetting(CLI_SETTING)

    def id(self):
        return "skysweep"

    def name(self):
        return "skysweep"

    def longName(self):
        if self.problem and not self.tables:
            return "skysweep: not available (see the log)"
        version = next(iter(self.tables.values()), {}).get("version", "?")
        return f"skysweep {version}: exact terrain horizons"

    def warningMessage(self):
        return self.problem or ""

    def loadAlgorithms(self):
        config = _processing_config()
        configured = config[0].getSetting(CLI_SETTING) if config else None
        self.cli, self.problem = command_line(configured)
        self.tables = {}
        if self.cli:
            self.tables, self.problem = option_tables(self.cli)
        if self.problem:
            # The message log is what QGIS shows (and qgis_process prints) when
            # a provider comes up without algorithms.
            QgsMessageLog.logMessage(self.problem, "skysweep", Qgis.Critical)
        for command, table in self.tables.items():
            self.addAlgorithm(SkysweepAlgorithm(self.cli, table))

    def supportedOutputRasterLayerExtensions(self):
        return ["tif"]

    def supportedOutputVectorLayerExtensions(self):
        return ["gpkg"]  # roofs writes a GeoPackage of several layers

    def defaultVectorFileExtension(self, hasGeometry=True):
        return "gpkg"
