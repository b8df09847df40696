"""homebench: a benchmark for robot visual homing on panoramic grid image databases."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("homebench")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"
