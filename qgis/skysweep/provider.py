"""The Processing provider: one algorithm per command."""
from qgis.core import QgsProcessingProvider

from .algorithms import SkysweepAlgorithm
from .cli import command_line, option_tables


class SkysweepProvider(QgsProcessingProvider):
    def __init__(self):
        super().__init__()
        self.cli = command_line()
        self.tables = option_tables(self.cli) if self.cli else {}

    def id(self):
        return "skysweep"

    def name(self):
        return "skysweep"

    def longName(self):
        version = next(iter(self.tables.values()), {}).get("version", "?")
        return f"skysweep {version}: exact terrain horizons"

    def loadAlgorithms(self):
        for command, table in self.tables.items():
            self.addAlgorithm(SkysweepAlgorithm(self.cli, table))

    def supportedOutputRasterLayerExtensions(self):
        return ["tif"]
