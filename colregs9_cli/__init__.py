"""colregs9: COLREGs rule 9 (narrow channels) audits of historical AIS."""

# The one place of the version: pyproject.toml reads it from here.
__version__ = "0.2.0"
