"""The installed distribution's version, in its own module: a clone folder named ``hiyari``
in a script's folder makes ``import hiyari`` a namespace package that skips
``hiyari/__init__.py``, and every module must still import (see tests/e2e/core)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("hiyari")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.0.0"
