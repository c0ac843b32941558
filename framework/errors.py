"""Errors that name the problem and the fix.

Every error a user can cause derives from :class:`PointatlasError`; the command-line
entry points print its message (no traceback) and exit non-zero.
"""
from __future__ import annotations


class PointatlasError(Exception):
    """A problem the user can fix; the message says what is wrong and how to fix it."""


class PluginError(PointatlasError):
    """A plugin is unknown, broken, or claimed twice."""


class ConfigError(PointatlasError, ValueError):
    """A configuration value is missing, misspelt, of the wrong type or out of range."""


class InputError(PointatlasError, ValueError):
    """Input data (points, files) cannot be used as given."""


class SchemaError(PointatlasError):
    """A results file was written by an incompatible (newer) schema."""
