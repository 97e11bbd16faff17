"""The benchmarks still run (quick sizes); their speed is measured by `make bench`, never here."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_every_benchmark_runs_quick(tmp_path):
    out = tmp_path / "bench.json"
    res = subprocess.run(
        [sys.executable, "-m", "benchmarks.run", "--quick", "--out", str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
    )
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-3000:]
    rows = json.loads(out.read_text())["rows"]
    modules = {p.stem.removeprefix("bench_") for p in (ROOT / "benchmarks").glob("bench_*.py")}
    assert len(modules) >= 6
    assert all(r["case"] != "FAILED" for r in rows)
    for r in rows:
        assert r["ours_s"] is None or r["ours_s"] > 0
        if r.get("peer_s"):
            assert abs(r["ratio"] - r["peer_s"] / r["ours_s"]) < 1e-9 * r["ratio"]
    # the two-thread rows come with the machine's ceiling: two serial marches at once
    pair = [r for r in rows if r["case"].startswith("the machine: two serial marches at once")]
    assert len(pair) == 1 and pair[0]["benchmark"] == "fmm threads"
    assert 0.2 < pair[0]["ratio"] < 5 and "ceiling" in pair[0]["notes"]
    # and name the threading layer the marches ran on
    threads = [r for r in rows if r["benchmark"] == "fmm threads" and r not in pair]
    assert threads and all("numba threading layer " in r["notes"] for r in threads)


def _probe(module: str, *args: str) -> str:
    """The standard output of ``python -m benchmarks.<module> <args>`` (exit status 0)."""
    res = subprocess.run([sys.executable, "-m", f"benchmarks.{module}", *args], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    return res.stdout


def _table(stdout: str, header: str) -> list[list[str]]:
    """The rows of the markdown table printed below the line starting with ``header``."""
    return [[c.strip() for c in line.split("|")[1:-1]] for line in stdout.splitlines()
            if line.startswith("| ") and not line.startswith(header)]


def test_the_march_pair_times_one_serial_march_alone_and_two_at_once():
    out = _probe("march_pair", "--case", "64x64:smooth", "--repeats", "1")
    assert "alone" in out and "at once" in out and "ceiling" in out


def test_the_machine_scaling_probe_times_its_five_loops_on_one_and_two_threads():
    rows = _table(_probe("machine_scaling", "--mb", "8", "--repeats", "1"), "| loop")
    assert [r[0] for r in rows] == ["compute", "l2", "stream", "lines", "gather"]
    for _, one, two, ratio in rows:
        one, two = float(one), float(two)
        assert one > 0 and two > 0
        assert float(ratio.removesuffix("x")) == pytest.approx(one / two, rel=0.02, abs=0.01)


def test_the_per_node_probe_marches_every_speed_map_over_the_same_nodes():
    rows = _table(_probe("march_per_node", "--sizes", "40", "--orders", "2"), "| grid")
    assert [r[2] for r in rows] == ["terrain", "uniform", "jittered"]
    assert {r[0] for r in rows} == {"40x40x40"} and {r[1] for r in rows} == {"2"}
    frozen = {int(r[4]) for r in rows}
    assert len(frozen) == 1 and 0 < frozen.pop() < 40 * 40 * 40  # the ground is never entered
    for r in rows:
        wall, per_node = float(r[3]), float(r[5])
        assert wall > 0
        assert per_node == pytest.approx(1e9 * wall / int(r[4]), rel=0.02, abs=1)


def test_the_first_touch_probe_maps_huge_and_small_pages_in_fresh_children():
    rows = _table(_probe("first_touch", "--mb", "8", "--repeats", "1", "--pause", "0"),
                  "| pages")
    assert [r[0].split()[0] for r in rows] == ["huge", "4"]
    small = rows[1]
    assert int(small[3]) >= 8 * 2**20 // 4096  # a fault per 4 KiB page touched
    for r in rows:
        assert float(r[1]) >= 0 and float(r[5]) > 0


def test_the_wait_policy_probe_marches_every_spin_count_on_one_and_two_threads():
    out = _probe("wait_policy", "--cases", "1100x1000:fm2", "--spins", "0", "2000",
                 "--repeats", "1")
    rows = _table(out.split("\n", 1)[1], "| case")
    assert [(r[0], r[1]) for r in rows] == [("1100x1000:fm2", "0"), ("1100x1000:fm2", "2000")]
    for r in rows:
        one, two = float(r[2]), float(r[3])
        assert one > 0 and two > 0 and float(r[4]) > 0
        assert float(r[6].removesuffix("x")) == pytest.approx(one / two, rel=0.02, abs=0.01)
    # the same code under both spin counts: the same times (one digest per thread count)
    assert rows[0][7] == rows[1][7]


def test_the_result_pages_probe_times_the_pool_and_a_fresh_array():
    out = _probe("result_pages", "--case", "fm2", "--shape", "1100x1000", "--threads", "2",
                 "--pause", "0", "--repeats", "2")
    assert "same times: True" in out.splitlines()[0]
    rows = _table(out.split("\n", 1)[1], "| result")
    assert [r[0] for r in rows] == ["pool", "fresh"]
    for r in rows:
        assert float(r[1]) > 0 and float(r[2]) >= 0 and float(r[3]) >= 0


def test_the_tuning_probe_marches_every_setting_and_says_when_the_times_stay_exact():
    out = _probe("tuning_ab", "--case", "1100x1000:fm2", "--repeats", "1", "--profile",
                 "{}", '{"WINDOW_NODES": {"(2, 1)": 65536}}')
    head, rest = out.split("\n", 1)
    assert head.startswith("1100x1000:fm2: one thread ")
    rows = _table(rest, "| setting")
    assert [r[0] for r in rows] == ["{}", '{"WINDOW_NODES": {"(2, 1)": 65536}}']
    one = float(head.split("one thread ")[1].split(" ms")[0])
    for r in rows:
        two = float(r[1])
        assert two > 0 and float(r[2].removesuffix("x")) == pytest.approx(one / two, rel=0.02)
        assert r[7] == "True"  # every setting: the serial march's times bit for bit (order 1
        # here: its slabs' times are the serial march's bit for bit on this map)
        assert float(r[8]) > 0 and float(r[10]) > 0 and len(r[12].split(" / ")) == 2
    assert int(rows[1][4]) < int(rows[0][4])  # wider windows: fewer of them
    # a name _tuning lacks is refused with the setting that named it; a case too small to
    # march on slabs is said
    for args, said in ((["{\"NO_SUCH\": 1}"], "_tuning has no 'NO_SUCH'"),
                       (["--case", "64x64:fm2", "{}"], "does not march on slabs")):
        res = subprocess.run([sys.executable, "-m", "benchmarks.tuning_ab", *args], cwd=ROOT,
                             capture_output=True, text=True, timeout=120)
        assert res.returncode == 1 and said in res.stderr
