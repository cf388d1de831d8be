"""Command-line interface (``tslip ...``); see :mod:`tslip.cli.main`."""

from .main import app, main

__all__ = ["app", "main"]
