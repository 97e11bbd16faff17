"""numba as the kernels use it: a kernel's cache goes stale when a callee in another module
changes (numba's own locators keep the old machine code), and the kernels use these locators."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fm2uav._kernel_stamp import PACKAGE

_KERNEL = """from numba import njit
from .helper import step

@njit(cache=True)
def kernel():
    return step()
"""
_HELPER = "from numba import njit\n\n@njit(cache=True)\ndef step():\n    return {value}\n"

_CHILD = """
import sys
from pathlib import Path
root, ours = Path(sys.argv[1]), sys.argv[2] == "1"
if ours:
    import fm2uav._numba as nb
    nb.KERNEL_ROOTS.append(root / "pkgk")
sys.path.insert(0, str(root))
from pkgk.kernel import kernel
print(kernel(), kernel.stats.cache_hits and "hit" or "miss")
"""


def _run(root: Path, ours: bool) -> list[str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(root / "cache")}
    done = subprocess.run([sys.executable, "-c", _CHILD, str(root), "1" if ours else "0"],
                          capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.split()


@pytest.mark.parametrize("ours", [False, True], ids=["numba's locators", "fm2uav's"])
def test_a_changed_callee_in_another_module_is_compiled_again(tmp_path, ours):
    pkg = tmp_path / "pkgk"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "kernel.py").write_text(_KERNEL)
    (pkg / "helper.py").write_text(_HELPER.format(value=1))
    assert _run(tmp_path, ours) == ["1", "miss"]
    assert _run(tmp_path, ours) == ["1", "hit"]  # cached
    (pkg / "helper.py").write_text(_HELPER.format(value=2))  # the kernel's file unchanged
    if ours:
        assert _run(tmp_path, ours) == ["2", "miss"]
        assert _run(tmp_path, ours) == ["2", "hit"]
    else:  # numba's limitation, the reason for fm2uav._numba: the old callee, from the cache
        assert _run(tmp_path, ours) == ["1", "hit"]


def test_every_kernel_module_takes_njit_from_fm2uav_numba():
    offenders = []
    for py in sorted(PACKAGE.rglob("*.py")):
        text = py.read_text(encoding="utf-8")
        if py.name == "_numba.py" or "numba" not in text:
            continue
        takes = any(line.lstrip().startswith("from ") and "_numba import" in line
                    for line in text.splitlines())
        decorates = re.search(r"^[ \t]*@(numba\.)?njit\b", text, re.M)
        if (decorates and not takes) or re.search(r"^[ \t]*from numba import njit", text, re.M):
            offenders.append(py.relative_to(PACKAGE).as_posix())
    assert not offenders, f"take njit from fm2uav._numba in {offenders}"


def test_the_kernels_are_stamped_by_fm2uavs_locators():
    from numba.core import caching

    import fm2uav._numba as nb
    from fm2uav.eikonal import _heap

    assert caching.CacheImpl._locator_classes[:3] == list(nb.LOCATORS)
    sift = _heap.sift_up  # a dispatcher with cache=True
    locator = sift._cache._impl.locator
    assert type(locator).__name__.startswith("Fm2uav")
    from fm2uav._kernel_stamp import kernel_stamp

    assert locator.get_source_stamp() == kernel_stamp(Path(_heap.__file__))
