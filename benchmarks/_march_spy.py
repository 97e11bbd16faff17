"""The parallel march watched from a benchmark's child process (issue 27)."""

from __future__ import annotations

import time


def watch_parallel_march() -> dict:
    """Wrap :func:`fm2uav.eikonal._parallel.march` and its windows' drivers (the regions'
    and the pipelines); returns the
    dict that each parallel march then fills: its statistics (``balance``, ``reopened``,
    ...), ``setup`` (the calling thread's CPU time [s] in the march outside the drivers:
    cuts, padding, plateau, unpadding) and ``drive_cpu`` (the process CPU time [s] in the
    drivers: the windows and exchanges of both threads). Cleared by the caller."""
    from fm2uav.eikonal import _parallel

    stats: dict = {}
    march = _parallel.march

    def spy(*args, **kwargs):
        stats.update(drive_main=0.0, drive_cpu=0.0)
        t = time.thread_time()
        T, s = march(*args, **kwargs)
        stats.update(s, setup=time.thread_time() - t - stats["drive_main"])
        return T, s

    def spy_drive(drive):
        def run(*args, **kwargs):
            t, c = time.thread_time(), time.process_time()
            out = drive(*args, **kwargs)
            stats["drive_main"] += time.thread_time() - t
            stats["drive_cpu"] += time.process_time() - c
            return out
        return run

    _parallel.march = spy
    for table in (_parallel._DRIVES, _parallel._PIPES):  # the regions' and the pipelines
        for key in list(table):
            table[key] = spy_drive(table[key])
    return stats
