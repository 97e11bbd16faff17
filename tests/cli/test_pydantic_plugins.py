"""pydantic's plugin loader without importlib.metadata (fm2uav.cli._pydantic_plugins).

Each case runs in a fresh interpreter (the stand-in acts once per process, before the first
model). These tests also pin the pydantic behaviour the stand-in relies on: with
``PYDANTIC_DISABLE_PLUGINS=__all__`` pydantic builds and validates models without calling
``entry_points``, and its loader imports nothing else from importlib.metadata.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

PROBE = """
import json, sys
from fm2uav.cli._pydantic_plugins import import_plugin_loader

used = import_plugin_loader()
from pydantic import BaseModel, Field


class M(BaseModel):
    x: float = Field(1.0, gt=0)


M(x=2.0)
before = "importlib.metadata" in sys.modules
import pydantic.plugin._loader as loader

plugins = list(loader.get_plugins())
lazy = sorted(str(e) for e in loader.entry_points(group="pydantic"))
import importlib.metadata as real

print(json.dumps({"used": used, "metadata_before": before, "plugins": len(plugins),
                  "same": lazy == sorted(str(e) for e in real.entry_points(group="pydantic")),
                  "real": type(real.entry_points).__name__ == "function"
                          and real.__name__ == "importlib.metadata"
                          and hasattr(real, "version")}))
"""


def _probe(disable: str | None) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYDANTIC_DISABLE_PLUGINS"}
    if disable is not None:
        env["PYDANTIC_DISABLE_PLUGINS"] = disable
    res = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                         timeout=300, env=env)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_with_plugins_disabled_models_build_without_importlib_metadata():
    for value in ("__all__", "1", "true"):  # pydantic's spellings of "no plugin"
        out = _probe(value)
        assert out["used"] is True, value
        assert out["metadata_before"] is False, value  # pydantic never asked for it
        assert out["plugins"] == 0
        # the loader's entry_points is the real one, imported on its first call
        assert out["same"] is True and out["real"] is True


def test_with_plugins_enabled_the_loader_is_pydantic_s_own():
    for value in (None, "", "some_plugin"):  # plugins may load: nothing is replaced
        out = _probe(value)
        assert out["used"] is False, value
        assert out["metadata_before"] is True, value  # pydantic read the entry points
        assert out["same"] is True and out["real"] is True
