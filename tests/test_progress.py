"""fm2uav.progress: stages and shares reported to a listener, nothing without one."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from fm2uav import progress
from fm2uav.progress import ProgressEvent, count, reporting, span, stage, step


def collect(work) -> list[ProgressEvent]:
    events: list[ProgressEvent] = []
    with reporting(events.append):
        work()
    return events


def test_steps_and_spans_divide_the_job_into_shares():
    def work():
        step("world", 0.2)
        step("plan", 0.6)
        with span("legs", 1.0):           # nested in "plan": its share of 0.2 .. 0.8
            for k in range(3):
                with span(f"leg {k + 1}", 1 / 3):
                    step("W", 0.5)
                    step("T", 0.5)
        step("files", 0.2)
    ev = collect(work)
    got = [(round(e.fraction, 4), e.message) for e in ev]
    assert got[0] == (0.0, "world")
    assert (0.2, "plan") in got and (0.2, "plan: legs") in got
    assert (0.2, "plan: legs: leg 1: W") in got
    assert (0.3, "plan: legs: leg 1: T") in got
    assert (0.6, "plan: legs: leg 3") in got and (0.7, "plan: legs: leg 3: T") in got
    assert (0.8, "files") in got
    assert got[-1] == (1.0, "done")
    f = [e.fraction for e in ev]
    assert f == sorted(f)                 # monotone


def test_shares_are_clamped_to_what_is_left_and_count_reports_items():
    def work():
        step("a", 0.9)
        step("b", 0.9)                    # only 0.1 left
        count(1, 4)
    ev = collect(work)
    assert [round(e.fraction, 3) for e in ev] == [0.0, 0.9, 0.925, 1.0]
    assert ev[2].message == "b (1 of 4)" and (ev[2].done, ev[2].total) == (1, 4)


def test_without_a_listener_everything_is_a_no_op():
    step("x", 0.5)
    count(1, 2)
    with span("y"):
        pass

    @stage("z")
    def f(a, b=2):
        """Doc."""
        return a + b
    assert f(1) == 3 and f.__doc__ == "Doc." and f.__name__ == "f"


def test_listeners_are_per_thread():
    seen: dict[str, list[str]] = {"main": [], "other": []}

    def other():
        with reporting(lambda e: seen["other"].append(e.message)):
            step("other work", 1.0)

    with reporting(lambda e: seen["main"].append(e.message)):
        t = threading.Thread(target=other)
        t.start()
        t.join()
        step("main work", 1.0)
    assert seen["main"] == ["main work", "done"]
    assert seen["other"] == ["other work", "done"]


def test_an_error_leaves_no_listener_behind():
    with pytest.raises(RuntimeError):
        with reporting(lambda e: None):
            raise RuntimeError("boom")
    assert progress._LISTENER.get() is None


def test_a_plan_reports_its_stages():
    from fm2uav import World, plan

    occ = np.zeros((40, 30), bool)
    occ[18:22, 0:20] = True
    ev = collect(lambda: plan(World(occ, spacing=1.0), (5.0, 5.0), (35.0, 5.0)))
    msgs = [e.message for e in ev]
    assert msgs[:3] == ["velocity map W", "arrival times T (Fast Marching)",
                        "path (geodesic descent)"]
    assert [round(e.fraction, 2) for e in ev[:3]] == [0.0, 0.3, 0.75]
