"""Optional dependencies (the pip extras): a feature that needs one refuses in its first second,
in one line naming what to install, instead of failing at its end.

A leaf module below every layer that offers an optional feature: the commands check their
options' needs here, and so does headless flying.
"""
from __future__ import annotations

import importlib.util

from fishgen.errors import MissingDependency


def needs(module: str, extra: str, feature: str, package: str | None = None) -> None:
    """``feature`` needs ``module`` (of the pip ``package``, when named otherwise): refuse now, in
    one line, if it is not installed."""
    if importlib.util.find_spec(module) is None:
        name = module if package is None else f"{package} ({module})"
        raise MissingDependency(f"{feature} needs {name}, which is not installed; install it with "
                                f"pip install 'fishgen[{extra}]'")
