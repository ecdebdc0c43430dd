"""The Processing provider "Strata": its four algorithms (docs/qgis.md)."""
from qgis.core import QgsProcessingProvider

from .commands import IngestAlgorithm, RenderAlgorithm
from .whatif import ErosionAlgorithm, FloodAlgorithm


class StrataProvider(QgsProcessingProvider):
    def id(self):
        return "strata"

    def name(self):
        return "Strata"

    def longName(self):  # noqa: N802 (QGIS's name)
        return "Strata: flood and erosion what-ifs, terrain stores and pictures"

    def loadAlgorithms(self):  # noqa: N802
        for algorithm in (FloodAlgorithm(), ErosionAlgorithm(), IngestAlgorithm(), RenderAlgorithm()):
            self.addAlgorithm(algorithm)
