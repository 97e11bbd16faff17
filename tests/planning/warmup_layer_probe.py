"""What a layer's warm-up leaves compiled for a later call of one kernel: run in a subprocess.

The layers above planning warm their own kernels (``fm2uav.vehicles.warmup``,
``fm2uav.baselines.warmup``, run by ``make install``). ``python warmup_layer_probe.py
MODULE KERNEL CODE`` runs every group of ``MODULE.GROUPS`` (``-``: none), then the Python
source ``CODE``, in one fresh process, and prints one JSON object: ``warm``, the
signatures of ``KERNEL`` (``package.module:function``) after the groups, and ``added``,
those ``CODE`` added beyond them (a later process would compile each of these).

The suite's cache is warm (``make install``), so the groups load their kernels from it.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path


def added_after(module: str | None, kernel: str, code: str) -> dict[str, list[str]]:
    """Run the probe in a subprocess: ``{"warm": [...], "added": [...]}`` (module docstring)."""
    res = subprocess.run([sys.executable, __file__, module or "-", kernel, code],
                         capture_output=True, text=True, env=os.environ.copy(), timeout=1800,
                         cwd=Path(__file__).resolve().parents[2])
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.splitlines()[-1])  # after the groups' "name: seconds" lines


def assert_covers(module: str, kernel: str, code: str) -> None:
    """After ``module``'s warm-up, ``code`` adds no signature to ``kernel``; without it, the
    same code adds exactly what the warm-up compiled (the check can fail)."""
    after = added_after(module, kernel, code)
    assert after["warm"] and after["added"] == []
    assert added_after(None, kernel, code)["added"] == after["warm"]


def main(argv: list[str]) -> int:
    module, kernel, code = argv
    mod_name, func = kernel.split(":")
    disp = getattr(importlib.import_module(mod_name), func)
    if module != "-":
        importlib.import_module(module).main([])
    warm = {str(s) for s in disp.signatures}
    exec(compile(code, "<workload>", "exec"), {})
    added = {str(s) for s in disp.signatures} - warm
    print(json.dumps({"warm": sorted(warm), "added": sorted(added)}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
