"""``python -m colregs9_cli``: the same as the ``colregs9`` console script."""

from .cli import run

run()
