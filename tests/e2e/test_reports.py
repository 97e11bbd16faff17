"""Every mission command writes report.html with --report: self-contained, the expected
traces and tables, --json on stdout, and no overwrite without --force (exit 2, files kept).

Each command runs once on its quickest setting (module fixture; formation: the documented
run of README.md, shared with the docs' run) and the tests read its outputs.
"""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()


def _bent_path(tmp_path):
    """A 2-leg path high over the open field (x_m,y_m,z_m), for ``fm2uav check``."""
    a = np.column_stack([np.linspace(300, 900, 41), np.full(41, 300.0), np.full(41, 540.0)])
    b = np.column_stack([np.full(41, 900.0), np.linspace(300, 900, 41), np.full(41, 540.0)])
    pts = np.vstack([a, b[1:]])
    f = tmp_path / "bent.csv"
    f.write_text("x_m,y_m,z_m\n" + "\n".join(",".join(f"{v:.3f}" for v in p) for p in pts) + "\n")
    return f


# name -> (arguments before --out, report files to check, trace names expected in the first,
#          table titles expected in the first)
CASES = {
    "run": (["run", "{mission}", "--report"],
            ["report.html"], ["FM² path", "terrain"], []),
    "export": (["export", "{bent}", "--scenario", "open-field", "--agl", "150"],
               ["report.html"], ["path", "terrain"], []),
    "cover": (["cover", "--area", "S3", "--spacing", "80", "--agl", "100"],
              ["report.html"],
              ["FM² path", "area", "bands", "terrain", "FM² path ideal (100 m AGL)",
               "FM² path start", "FM² path goal"], []),
    "formation": (["formation", "--scenario", "fissure", "--level", "7"],
                  ["report.html"],
                  ["leader", "follower 1", "follower 2", "leader FM² plan",
                   "leader ideal (105 m AGL)", "terrain"], ["UAVs"]),
    "check": (["check", "{bent}", "--scenario", "open-field", "--airframe", "disco"],
              ["report.html"],
              ["planned", "flown (disco)", "terrain", "planned AGL"], []),
    "check-bare": (["check", "{bent}", "--airframe", "disco"],
                   ["report.html"],
                   ["planned", "flown (disco)", "planned altitude"], []),
    "tune": (["tune", "--p1", "0.5", "--p2", "1.3,1.5"],
             ["report.html"], ["terrain"],
             ["The tuned path", "Pareto front (deviation ↓, max climb ↓, min turn radius ↑)"]),
    "reproduce-tff": (["reproduce", "tff"],
                      ["report.html"],
                      ["level 2 (p1=0.5, p2=2.5)", "level 5 (p1=0.5, p2=1.5)",
                       "level 10 (p1=0.5, p2=1.3)", "smooth p2=0.8 (p1=0.5, p2=0.8)",
                       "level 10 (p1=0.5, p2=1.3) ideal (150 m AGL)", "terrain"],
                      ["Terrain-following cases"]),
    "reproduce-city": (["reproduce", "city", "--rrt-time", "0.5", "--rrtstar-time", "0.3"],
                       ["report.html"],
                       ["FM² low W^1", "FM² low W^0.25", "FM² high W^0.5",
                        "flown tracks (disco)", "obstacles"],
                       ["Safety and separation distances (Tables 3.1/3.2)",
                        "FM² vs RRT, low altitude"]),
    "reproduce-coverage": (["reproduce", "coverage"],
                           ["report.html"],
                           ["S1 FM² path", "S2 FM² path", "S3 FM² path", "S4 FM² path",
                            "S1 area", "S4 bands", "terrain"],
                           ["Table 5.1 — D = 80 m", "Table 5.2 — S1, different D"]),
    "reproduce-formation": (["reproduce", "formation", "--no-gif"],
                            ["report.html", "case1/report.html", "case2/report.html",
                             "case2-thesis-p/report.html"],
                            ["case 1: no flight level, walls, relief to 36 cells, dist 120 m"
                             " — leader",
                             "case 1 on the stand-in relief (flies over the ridges) — leader",
                             "case 2: level 7, p1 = 0.5, p2 = 1.5 — leader",
                             "case 2: level 7, p1 = 0.5, p2 = 1.5 — leader ideal (105 m AGL)"],
                            ["Results (thesis ch. 6)"]),
}


#: The default mission; the run case writes it with ``outputs.formats: [csv, json]`` (no
#: html), so that ``run --report`` must add report.html.
MISSION = Path(__file__).resolve().parents[2] / "examples" / "open_field_tff.yaml"


def test_every_command_accepts_report():
    """README: "Every command that writes files accepts --report" — every command and
    reproduction with an --out (``fm2uav app`` serves pages and writes no output set)."""
    from typer.main import get_command

    cli = get_command(app)
    seen = []
    for name, cmd in cli.commands.items():
        subs = getattr(cmd, "commands", None) or {name: cmd}
        for sub_name, sub in subs.items():
            opts = {o for p in sub.params for o in getattr(p, "opts", [])}
            if "--out" in opts:
                seen.append((name, sub_name, "--report" in opts))
    assert len(seen) >= 14 and all(ok for *_, ok in seen), [s for s in seen if not s[2]]


#: the reproductions take tens of seconds each: their cases are marked slow
SLOW = {name for name in CASES if name.startswith("reproduce-")}


def _cases():
    return [pytest.param(name, marks=pytest.mark.slow) if name in SLOW else name
            for name in CASES]


@pytest.fixture(scope="module")
def runs(tmp_path_factory, cli_once):
    """Every command run once, when a test first asks for it, with --report --json:
    name -> (result, out dir, args). The reproductions go through the session's
    ``cli_once`` (tests/conftest.py), shared with tests/cli/test_cmd_city.py, test_cmd_tff.py,
    test_cmd_formation.py; formation's is also the docs' run of ``fm2uav formation --scenario
    fissure --level 7`` (README.md, with --report --json)."""
    tmp = tmp_path_factory.mktemp("cli_reports")
    bent = str(_bent_path(tmp))

    class Runs(dict):
        def __missing__(self, name):
            mission = tmp / "mission.yaml"
            mission.write_text(MISSION.read_text().split("outputs:")[0]
                               + "outputs: {formats: [csv, json]}\n")
            subs = {"{bent}": bent, "{mission}": str(mission)}
            args = [subs.get(a, a) for a in CASES[name][0]]
            r = cli_once(args + ["--report", "--json"])
            self[name] = (r.result, r.out, args)
            return self[name]

    return Runs()


def _figure(html: str, div_id: str) -> list[dict]:
    """The traces of the plotly figure drawn into ``div_id``."""
    m = re.search(r'Plotly\.newPlot\(\s*"' + re.escape(div_id) + r'",\s*', html)
    assert m, f"no plotly figure {div_id}"
    data, _ = json.JSONDecoder().raw_decode(html, m.end())
    return data


def _snapshot(out):
    return {p.relative_to(out): (p.stat().st_size, p.stat().st_mtime_ns,
                                 hashlib.sha1(p.read_bytes()).hexdigest())
            for p in sorted(out.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("name", _cases())
def test_report_written_self_contained_with_expected_traces(runs, name):
    res, out, _ = runs[name]
    assert res.exit_code == 0, res.output
    _, reports, traces, tables = CASES[name]
    for rel in reports:
        html = (out / rel).read_text(encoding="utf-8")
        assert html.startswith("<!DOCTYPE html>")
        # self-contained: no script fetched from the network, plotly.js inlined
        assert not re.search(r"<script[^>]*src=[\"']?https?://", html), rel
        assert len(html) > 1_000_000  # plotly.js inlined
        assert html.count('class="plotly-graph-div"') == 2, rel
        for div in ("fm2uav-scene", "fm2uav-profiles"):
            assert _figure(html, div), (rel, div)
    html = (out / reports[0]).read_text(encoding="utf-8")
    names = {t.get("name") for div in ("fm2uav-scene", "fm2uav-profiles")
             for t in _figure(html, div)}
    missing = [t for t in traces if t not in names]
    assert not missing, (missing, sorted(n for n in names if n))
    for title in tables:
        assert f"<h2>{title}</h2>" in html, title


@pytest.mark.parametrize("name", _cases())
def test_json_summary_parses_and_lists_report(runs, name):
    res, out, _ = runs[name]
    payload = json.loads(res.stdout)  # --json: stdout is one JSON document, nothing else
    assert isinstance(payload, dict) and payload
    if "files" in payload:
        assert str(out / "report.html") in payload["files"]


@pytest.mark.parametrize("name", _cases())
def test_second_run_without_force_exits_2_and_keeps_files(runs, name):
    _, out, args = runs[name]
    before = _snapshot(out)
    res = runner.invoke(app, args + ["--report", "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert "--force" in res.output and "already exists" in res.output
    assert _snapshot(out) == before  # nothing rewritten, no temporary files left


def test_tune_report_shows_the_best_path(runs):
    _, out, _ = runs["tune"]
    best = json.loads((out / "tune.json").read_text())["best"]
    html = (out / "report.html").read_text(encoding="utf-8")
    names = {t.get("name") for t in _figure(html, "fm2uav-scene")}
    # beside the map: the parameters chosen and whether they keep the airframe's limits
    aside = html[html.index("<aside"):html.index("</aside>")]
    if best is None:
        assert any(n and n.startswith("closest (breaks the limits)") for n in names), names
        assert "closest parameters" in aside and "NOT kept by any candidate" in aside
    else:
        assert "tuned parameters" in aside and f"p1 {best['p1']:g}, p2 {best['p2']:g}" in aside
        assert "<td>kept (max climb" in aside
        label = f"best: p1={best['p1']:g}, p2={best['p2']:g}, α={best['saturation']:g}"
        assert label in names and f"{label} ideal (150 m AGL)" in {
            t.get("name") for t in _figure(html, "fm2uav-profiles")}


def test_formation_report_tracks_are_the_csv_trajectories(runs):
    """The drawn UAV tracks are exactly the positions written to trajectories.csv."""
    from fm2uav.io.trajectories import read_trajectories_csv

    _, out, _ = runs["formation"]
    times, pos, uavs = read_trajectories_csv(out / "trajectories.csv")
    scene = {t["name"]: t for t in _figure((out / "report.html").read_text(encoding="utf-8"),
                                           "fm2uav-scene")}
    for i, uav in enumerate(uavs):
        xyz = np.column_stack([_arr(scene[uav][k]) for k in "xyz"])
        np.testing.assert_allclose(xyz, pos[:, i], atol=1e-3)


def _arr(v):
    """A plotly trace array: a list, or a typed array {"dtype", "bdata"} (base64)."""
    if isinstance(v, dict) and "bdata" in v:
        import base64

        return np.frombuffer(base64.b64decode(v["bdata"]), dtype=np.dtype(v["dtype"]))
    return np.asarray(v, dtype=float)


def test_check_without_scenario_has_no_ground(runs):
    _, out, _ = runs["check-bare"]
    html = (out / "report.html").read_text(encoding="utf-8")
    names = {t.get("name") for t in _figure(html, "fm2uav-profiles")}
    assert not any(n and (n.endswith("AGL") or n.endswith("ground")) for n in names), names
    assert "none given (paths only)" in html


def test_quiet_prints_nothing(tmp_path):
    res = runner.invoke(app, ["tune", "--p1", "0.5", "--p2", "1.3", "--quiet", "--report",
                              "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert res.output == ""
    assert (tmp_path / "report.html").exists()


def test_bad_input_is_checked_before_any_work(tmp_path):
    """A clash on report.html alone is found before planning (exit 2, nothing written)."""
    (tmp_path / "report.html").write_text("mine")
    res = runner.invoke(app, ["cover", "--area", "S3", "--spacing", "80", "--report",
                              "--out", str(tmp_path)])
    assert res.exit_code == 2 and "report.html already exists" in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.html"]
    assert (tmp_path / "report.html").read_text() == "mine"


def test_formation_report_renders_in_headless_chromium(runs):
    """Open the formation report in Chromium: no JS error, file-only requests, a WebGL
    scene with every UAV's track, and a non-blank screenshot showing the coloured tracks."""
    from tests.viz.cdp import Browser, find_chromium

    chromium = find_chromium()
    if chromium is None:
        pytest.skip("Chromium is not installed (Debian: apt-get install -y chromium)")
    _, out, _ = runs["formation"]
    ready = ("(() => { const d = document.querySelectorAll('.js-plotly-plot');"
             " return d.length === 2 && Array.from(d).every(g => g._fullLayout); })()")
    probe = ("(() => { const g = document.getElementById('fm2uav-scene');"
             " const s = g._fullLayout.scene._scene;"
             " return {webgl: !!(s && s.glplot), names: g.data.map(t => t.name),"
             " tables: document.querySelectorAll('table').length}; })()")
    with Browser(chromium, timeout=60) as b:
        r = b.load((out / "report.html").as_uri(), ready_js=ready, probe_js=probe)
    assert r.errors == [], r.errors
    assert r.requests and all(u.startswith(("file:", "data:", "blob:")) for u in r.requests)
    assert r.probe["webgl"] is True
    assert {"leader", "follower 1", "follower 2"} <= set(r.probe["names"])
    assert r.probe["tables"] >= 4          # parameters, metrics, world, UAVs
    import io

    import matplotlib.image as mpimg

    img = mpimg.imread(io.BytesIO(r.screenshot), format="png")[..., :3]
    scene = img[150:700, 200:1100]
    assert (~np.all(scene > 0.97, axis=-1)).mean() > 0.15       # not blank
    red = (scene[..., 0] > 0.7) & (scene[..., 1] < 0.35) & (scene[..., 2] < 0.35)
    blue = (scene[..., 2] > 0.6) & (scene[..., 0] < 0.3)
    assert red.sum() > 100 and blue.sum() > 100                 # leader and follower 1
