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


def test_the_machine_scaling_probe_times_its_five_loops_on_one_and_two_threads():
    res = subprocess.run([sys.executable, "-m", "benchmarks.machine_scaling", "--mb", "8",
                          "--repeats", "1"], cwd=ROOT, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    rows = [line.split("|")[1:-1] for line in res.stdout.splitlines()
            if line.startswith("| ") and not line.startswith("| loop")]
    assert [r[0].strip() for r in rows] == ["compute", "l2", "stream", "lines", "gather"]
    for _, one, two, ratio in rows:
        one, two = float(one), float(two)
        assert one > 0 and two > 0
        assert float(ratio.strip().removesuffix("x")) == pytest.approx(one / two, rel=0.02,
                                                                        abs=0.01)
