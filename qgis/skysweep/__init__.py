"""skysweep's Processing provider (doc/qgis.md)."""


def classFactory(iface):
    from .plugin import SkysweepPlugin
    return SkysweepPlugin(iface)
