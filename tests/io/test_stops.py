"""fm2uav.io._stops: the stop signals without the output sets' machinery."""

from __future__ import annotations

import json
import subprocess
import sys

from fm2uav.io import _stops, outdir


def test_outdir_re_exports_the_same_objects():
    for name in (*_stops.__all__, "_ACTIVE", "_Commit", "_on_stop_signal", "_signals_held"):
        assert getattr(outdir, name) is getattr(_stops, name), name
    assert outdir._ACTIVE is _stops._ACTIVE  # one list of active sets for both modules


def test_importing_it_loads_no_output_set_machinery():
    code = ("import json, sys; import fm2uav.io._stops; print(json.dumps([m for m in "
            "('fm2uav.io.outdir', 'shutil', 'tempfile') if m in sys.modules]))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout) == []


def test_finish_all_without_any_set_commits(monkeypatch):
    monkeypatch.setattr(_stops._Commit, "done", False)
    assert _stops.active_sets() == []
    _stops.finish_all()
    assert _stops._Commit.done
