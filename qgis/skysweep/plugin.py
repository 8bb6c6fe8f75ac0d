"""Registers the provider with Processing, in the QGIS desktop and in
qgis_process alike (initProcessing)."""
from qgis.core import QgsApplication

from .provider import SkysweepProvider


class SkysweepPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):
        self.provider = SkysweepProvider()
        QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
