"""Strata's QGIS plugin: a Processing provider (issue 32; docs/qgis.md).

QGIS finds it in a plugins folder (`cmake --install` puts it in <prefix>/share/qgis/python/plugins;
QGIS_PLUGINPATH names that folder for a prefix other than /usr) and calls classFactory.
"""


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import StrataPlugin
    return StrataPlugin(iface)
