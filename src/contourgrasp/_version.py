"""The package version: one home, read by the package and by the files it writes."""

__version__ = "0.2.0"
