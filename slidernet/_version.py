"""The installed version of slidernet, recorded in every result and checkpoint."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("slidernet")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
