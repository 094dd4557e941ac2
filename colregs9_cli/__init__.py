"""colregs9: COLREGs rule 9 (narrow channels) audits of historical AIS."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("colregs9")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"
