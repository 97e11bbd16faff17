"""The app's vendored JavaScript is what scripts/vendor_js.py recorded (versions, licences, sha256)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
VENDOR = ROOT / "src" / "fm2uav" / "viz" / "web" / "vendor"


def _script():
    spec = importlib.util.spec_from_file_location("vendor_js", ROOT / "scripts" / "vendor_js.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_committed_files_match_the_record_and_the_pinned_versions():
    assert _script().check() == []


def test_every_package_keeps_its_licence_and_is_listed_for_people():
    record = json.loads((VENDOR / "VENDORED.json").read_text())
    md = (VENDOR / "VENDORED.md").read_text()
    for name, p in record["packages"].items():
        assert p["license"] in ("MIT", "BSD-2-Clause", "ISC", "BSD-3-Clause", "Apache-2.0")
        licence = [f for f in p["files"] if f.endswith("LICENSE")]
        assert licence and (VENDOR / licence[0]).read_text().strip()
        assert f"| `{name}` | {p['version']} | {p['license']} |" in md


def test_the_page_loads_only_vendored_or_own_files():
    import re

    html = (ROOT / "src" / "fm2uav" / "app" / "static" / "index.html").read_text()
    refs = re.findall(r'(?:src|href)="([^"]+)"', html)
    assert refs and all(r.startswith(("/web/", "/static/")) for r in refs), refs
