"""The package's version, on the ground floor: the top level hands it on (``cd.__version__``)
and the design.json provenance records it, neither importing the other."""

__version__ = "0.1.0"
