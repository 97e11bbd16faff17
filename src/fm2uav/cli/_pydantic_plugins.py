"""pydantic's plugin loader without :mod:`importlib.metadata` where no plugin is loaded.

``pydantic.plugin._loader`` imports :mod:`importlib.metadata` when the first model is
built (``from importlib.metadata import entry_points``, with email, zipfile, csv, socket:
~40 M instructions, ~4 % of ``fm2uav run bad.yaml``) and calls ``entry_points`` only when
plugins are enabled. The command line disables them (``PYDANTIC_DISABLE_PLUGINS=__all__``,
:func:`fm2uav.__main__.main`), so :func:`import_plugin_loader` imports the loader with a
stand-in :mod:`importlib.metadata` that holds a lazy ``entry_points`` (the real one,
imported on first call) and is taken out of ``sys.modules`` at once.

Nothing changes where plugins may load (the variable unset or naming plugins), where
:mod:`importlib.metadata` or the loader are imported already, or where the loader wants
more than ``entry_points`` (a later pydantic): then the loader is imported as pydantic
imports it. tests/cli/test_pydantic_plugins.py fails when pydantic's loader or its
reading of ``PYDANTIC_DISABLE_PLUGINS`` change under this.
"""

from __future__ import annotations

import os
import sys
import types
from typing import Any

__all__ = ["import_plugin_loader", "plugins_disabled"]

#: The values of ``PYDANTIC_DISABLE_PLUGINS`` with which pydantic loads no plugin (and
#: calls no ``entry_points``): pydantic.plugin._loader.get_plugins.
DISABLED = ("__all__", "1", "true")
_LOADER = "pydantic.plugin._loader"
_METADATA = "importlib.metadata"


def plugins_disabled() -> bool:
    """Whether pydantic loads no plugin in this process (``PYDANTIC_DISABLE_PLUGINS``)."""
    return os.environ.get("PYDANTIC_DISABLE_PLUGINS") in DISABLED


def _entry_points(**params: Any) -> Any:
    """:func:`importlib.metadata.entry_points`, imported on first call."""
    from importlib.metadata import entry_points

    return entry_points(**params)


def import_plugin_loader() -> bool:
    """Import ``pydantic.plugin._loader`` without :mod:`importlib.metadata` when plugins
    are disabled (see the module's docstring); True when the stand-in served.

    Call it before the first pydantic model of the process is built.
    """
    if not plugins_disabled() or _METADATA in sys.modules or _LOADER in sys.modules:
        return False
    import pydantic.plugin  # noqa: F401  (pydantic and pydantic_core: imported as usual)

    stand_in = types.ModuleType(_METADATA, "importlib.metadata's entry_points, imported lazily")
    stand_in.entry_points = _entry_points  # type: ignore[attr-defined]
    sys.modules[_METADATA] = stand_in
    try:
        import pydantic.plugin._loader  # noqa: F401
    except ImportError:  # the loader imports more than entry_points: as pydantic does
        sys.modules.pop(_LOADER, None)
    finally:
        if sys.modules.get(_METADATA) is stand_in:
            del sys.modules[_METADATA]
    if _LOADER in sys.modules:
        return True
    import pydantic.plugin._loader  # noqa: F401, F811

    return False
