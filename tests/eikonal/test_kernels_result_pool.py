"""The pool of result arrays (``_kernels.result_array``): a march's times land in pages a
freed result left, never in memory a live result or any view of it still holds."""

from __future__ import annotations

import gc
import threading

import numpy as np
import pytest

from fm2uav.eikonal import _kernels, fast_marching

N = 1_000_000  # 8 MB: pooled (at least 4 MiB)
ROOM = 2  # pooled mappings each test may have beside those other tests' results still hold


def _addr(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


@pytest.fixture(autouse=True)
def base(monkeypatch):
    """Each test starts with no free pooled mapping and room for :data:`ROOM` of its own
    beside the pooled results other tests still hold (their number: the fixture's value)."""
    gc.collect()
    with _kernels._RESULTS_LOCK:
        _kernels._RESULTS_FREE.clear()
        held = _kernels._RESULTS_LIVE[0]
    monkeypatch.setattr(_kernels, "RESULT_KEEP", held + ROOM)
    yield held
    gc.collect()
    with _kernels._RESULTS_LOCK:
        _kernels._RESULTS_FREE.clear()


def test_a_freed_result_s_mapping_is_reused():
    a = _kernels.result_array(N)
    where = _addr(a)
    assert a.dtype == np.float64 and a.shape == (N,) and a.flags.writeable
    del a
    b = _kernels.result_array(N)
    assert _addr(b) == where


def test_a_view_keeps_the_mapping_busy():
    a = _kernels.result_array(N)
    a[:] = 7.0
    view = a.reshape(1000, 1000)[10:20]
    del a
    gc.collect()
    b = _kernels.result_array(N)
    b[:] = -1.0
    assert not np.shares_memory(view, b)
    assert np.all(view == 7.0)
    del view
    c = _kernels.result_array(N)  # the first mapping is free again
    assert not np.shares_memory(b, c)


def test_live_results_never_share_memory_and_the_pool_is_bounded(base):
    live = [_kernels.result_array(N) for _ in range(ROOM + 2)]
    for i, a in enumerate(live):
        a[:] = i
    for i, a in enumerate(live):
        assert np.all(a == i)
        for b in live[i + 1:]:
            assert not np.shares_memory(a, b)
    assert _kernels._RESULTS_LIVE[0] == base + ROOM  # the other two: plain arrays
    del live
    gc.collect()
    assert len(_kernels._RESULTS_FREE) == ROOM
    assert _kernels._RESULTS_LIVE[0] == base


def test_a_larger_result_replaces_a_smaller_free_mapping():
    small = [_kernels.result_array(N) for _ in range(ROOM)]
    del small
    gc.collect()
    big = _kernels.result_array(3 * N)
    big[:] = 1.0
    assert len(_kernels._RESULTS_FREE) == ROOM - 1
    assert max(len(m) for m in _kernels._RESULTS_FREE) < 8 * 3 * N
    del big
    gc.collect()
    assert max(len(m) for m in _kernels._RESULTS_FREE) >= 8 * 3 * N


def test_small_and_huge_results_are_plain_arrays(base, monkeypatch):
    small = _kernels.result_array(1000)
    assert small.base is None
    monkeypatch.setattr(_kernels, "WORK_KEEP_MAX", 4 * N)  # 8 MB is "huge" now
    huge = _kernels.result_array(N)
    assert huge.base is None
    assert not _kernels._RESULTS_FREE and _kernels._RESULTS_LIVE[0] == base


def test_threads_taking_and_freeing_results(base):
    errors = []

    def work(k):
        for _ in range(30):
            a = _kernels.result_array(N)
            a[:] = k
            if not np.all(a == k):
                errors.append(k)
            del a

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    gc.collect()
    assert not errors
    assert _kernels._RESULTS_LIVE[0] == base
    assert len(_kernels._RESULTS_FREE) <= ROOM


@pytest.mark.parametrize("threads", [1, 2])
def test_marches_into_a_recycled_mapping_give_the_same_times(threads):
    rng = np.random.default_rng(3)
    speed = 0.5 + rng.random((1100, 1000))
    first = fast_marching(speed, [(300, 400)], order=1, threads=threads)
    keep = first.copy()
    where = _addr(first)
    del first
    gc.collect()
    again = fast_marching(speed, [(300, 400)], order=1, threads=threads)
    assert _addr(again) == where  # the same pages, every time written anew
    np.testing.assert_array_equal(again, keep)
    held = fast_marching(speed, [(10, 10)], order=1, threads=threads)  # `again` still alive
    assert not np.shares_memory(held, again)
    np.testing.assert_array_equal(again, keep)


def test_the_pool_says_whether_a_result_s_pages_are_there():
    a, resident = _kernels.pooled_result_array(N)
    assert not resident  # a new mapping (the fixture freed none): its pages fault in
    del a
    b, resident = _kernels.pooled_result_array(N)
    assert resident  # a's mapping, whose pages a's writes faulted in
    small, resident = _kernels.pooled_result_array(1000)  # not pooled
    assert not resident and small.size == 1000


def test_a_pooled_result_takes_no_page_toucher_thread(monkeypatch):
    """The parallel march starts a thread to fault in a fresh result's pages beside the cuts'
    coarse march; a result from the pool has its pages (and the scan gave the top speed):
    no thread, the same times."""
    from fm2uav.eikonal import _parallel

    made = []

    class Spy(_parallel._PageToucher):
        def __init__(self, *arrays, top_of=None):
            made.append((len(arrays), top_of is not None))
            super().__init__(*arrays, top_of=top_of)

    monkeypatch.setattr(_parallel, "_PageToucher", Spy)
    v = np.ones((1100, 1000))  # 8.8 MB of times: from the pool
    v[500:520, 100:900] = 0.0
    a = fast_marching(v, [(3, 4)], order=1, threads=2).copy()  # its mapping back to the pool
    assert made == [(2, False)]  # a new mapping's pages; the top speed from the scan
    made.clear()
    b = fast_marching(v, [(3, 4)], order=1, threads=2)  # in a's pages
    np.testing.assert_array_equal(b, a)
    assert made == []
