"""The work buffers' page advice (``_kernels._work``): huge pages by default, small pages
where asked (``huge=False``), and the parallel march's lean-layout times as
``_tuning.LEAN_TIMES_HUGE`` says (docs/performance.md, "The terrain march's times on small
pages")."""

from __future__ import annotations

import mmap
from pathlib import Path

import numpy as np
import pytest

from fm2uav.eikonal import _kernels, _parallel, _tuning, fast_marching

SMAPS = Path("/proc/self/smaps")
pytestmark = pytest.mark.skipif(
    not SMAPS.exists() or not hasattr(mmap, "MADV_NOHUGEPAGE")
    or not hasattr(mmap, "MADV_HUGEPAGE"),
    reason="needs Linux's /proc/self/smaps and madvise's huge-page advice")


def _vm_flags(a: np.ndarray) -> set[str]:
    """The VmFlags of the mapping holding ``a``'s first byte (``hg``: advised for huge
    pages, ``nh``: against them)."""
    addr = a.__array_interface__["data"][0]
    inside = False
    for line in SMAPS.read_text().splitlines():
        head = line.split()[0]
        if "-" in head and ":" not in head:
            lo, hi = (int(x, 16) for x in head.split("-"))
            inside = lo <= addr < hi
        elif inside and head == "VmFlags:":
            return set(line.split()[1:])
    raise AssertionError(f"no mapping holds {addr:#x}")


@pytest.mark.parametrize(("huge", "flag", "other"), [(True, "hg", "nh"), (False, "nh", "hg")])
def test_work_memory_is_advised_as_asked(huge, flag, other):
    a = _kernels._work(8 * 2**20, huge=huge)
    flags = _vm_flags(a)
    assert flag in flags and other not in flags
    a[::4096] = 1  # usable either way
    assert int(a[::4096].sum()) == a[::4096].size


def test_small_work_memory_is_a_plain_array():
    # below 4 MiB no mapping of its own: numpy's allocation, whatever its advice
    a = _kernels._work(2**20, huge=False)
    assert a.size == 2**20 and a.dtype == np.uint8


@pytest.mark.parametrize("huge", [True, False])
def test_the_parallel_lean_march_maps_its_times_as_tuned(huge, monkeypatch):
    """The lean layout forced on a small 3D grid, on two threads: its times' buffer is
    advised as ``LEAN_TIMES_HUGE`` says, its speeds' for huge pages, and the times are those
    of either setting and of the serial lean march, bit for bit."""
    monkeypatch.setattr(_kernels, "LEAN_NODES", 0)
    monkeypatch.setattr(_tuning, "PARALLEL_MIN_NODES", 0)
    monkeypatch.setattr(_tuning, "ORDER2_MIN_NODES_3D", 0)
    monkeypatch.setattr(_tuning, "MIN_SLAB_NODES", 0)
    monkeypatch.setattr(_tuning, "LEAN_TIMES_HUGE", huge)
    seen = []
    buffers = _kernels._buffers

    def spy(*args, **kwargs):
        out = buffers(*args, **kwargs)
        seen.append((_vm_flags(out[0]), _vm_flags(out[1]), out[0].nbytes))
        return out

    monkeypatch.setattr(_kernels, "_buffers", spy)
    rng = np.random.default_rng(0)
    speed = 1.0 + rng.random((160, 80, 80))  # padded: V's 4 bytes a node above 4 MiB too
    src = [(50, 40, 40)]
    two = fast_marching(speed, src, order=2, threads=2)
    assert seen, "the parallel march mapped no lean buffers"
    t_flags, v_flags, nbytes = seen[0]
    assert nbytes >= 8 * 2**20
    assert ("hg" if huge else "nh") in t_flags
    assert "hg" in v_flags
    one = fast_marching(speed, src, order=2, threads=1)
    assert np.array_equal(one, two)
    assert _parallel.on_slabs(speed.size, True, 2)
