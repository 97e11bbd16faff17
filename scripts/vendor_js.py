"""Vendor the app's JavaScript libraries from the npm registry into the package.

Run from the repository root (needs ``npm``; the result is committed, so neither
the app nor CI needs npm or a network)::

    python scripts/vendor_js.py            # fetch the pinned versions, copy, record
    python scripts/vendor_js.py --check    # verify the committed files against VENDORED.json

For each pinned package, ``npm pack NAME@VERSION`` downloads its registry tarball
into a temporary folder; the listed distribution files and the package's LICENSE
are copied to ``src/fm2uav/viz/web/vendor/<dir>/``, and
``src/fm2uav/viz/web/vendor/VENDORED.json`` records the version, licence,
tarball integrity (npm's sha512) and the sha256 of every copied file;
``VENDORED.md`` says the same for people.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VENDOR = ROOT / "src" / "fm2uav" / "viz" / "web" / "vendor"

#: npm package → (version, folder under vendor/, files of the tarball's ``package/`` to copy,
#: what the app uses it for).
PACKAGES: dict[str, tuple[str, str, tuple[str, ...], str]] = {
    "leaflet": ("1.9.4", "leaflet", (
        "dist/leaflet.js", "dist/leaflet.css", "dist/images/layers.png",
        "dist/images/layers-2x.png", "dist/images/marker-icon.png",
        "dist/images/marker-icon-2x.png", "dist/images/marker-shadow.png", "LICENSE"),
        "the map: raster DEM tiles, vector layers, scale bar (no WebGL needed)"),
    "@geoman-io/leaflet-geoman-free": ("2.20.2", "leaflet-geoman", (
        "dist/leaflet-geoman.min.js", "dist/leaflet-geoman.css", "LICENSE"),
        "drawing and editing no-fly zones (polygons, circles) and survey areas"),
    "uplot": ("1.6.32", "uplot", (
        "dist/uPlot.iife.min.js", "dist/uPlot.min.css", "LICENSE"),
        "the altitude / ground profile chart"),
}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def vendor() -> dict:
    """Download, copy and record every package; returns the VENDORED.json document."""
    if shutil.which("npm") is None:
        sys.exit("npm is needed to vendor the JavaScript libraries (apt-get install npm)")
    record: dict = {"generated_by": "scripts/vendor_js.py", "packages": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for name, (version, folder, files, use) in PACKAGES.items():
            out = subprocess.run(["npm", "pack", f"{name}@{version}", "--json", "--silent"],
                                 cwd=tmp, check=True, capture_output=True, text=True).stdout
            info = json.loads(out)[0]
            tgz = Path(tmp) / info["filename"]
            with tarfile.open(tgz) as tar:
                tar.extractall(Path(tmp) / folder, filter="data")
            pkg = Path(tmp) / folder / "package"
            meta = json.loads((pkg / "package.json").read_text())
            dest = VENDOR / folder
            if dest.exists():
                shutil.rmtree(dest)
            copied = {}
            for f in files:
                target = dest / Path(f).name if f.startswith("dist/") and "/images/" not in f \
                    else dest / f.removeprefix("dist/")
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(pkg / f, target)
                copied[str(target.relative_to(VENDOR))] = _sha256(target)
            record["packages"][name] = {
                "version": meta["version"], "license": meta.get("license"),
                "homepage": meta.get("homepage"), "integrity": info.get("integrity"),
                "used_for": use, "files": copied}
    (VENDOR / "VENDORED.json").write_text(json.dumps(record, indent=2) + "\n")
    lines = ["# Vendored JavaScript", "",
             "Copied from the npm registry by `python scripts/vendor_js.py` (do not edit by "
             "hand; run the script after changing a pinned version). Each folder holds the "
             "package's own LICENSE.", "",
             "| package | version | licence | used for |", "|---|---|---|---|"]
    for name, p in record["packages"].items():
        lines.append(f"| `{name}` | {p['version']} | {p['license']} | {p['used_for']} |")
    lines += ["", "sha256 of every file: `VENDORED.json`."]
    (VENDOR / "VENDORED.md").write_text("\n".join(lines) + "\n")
    return record


def check() -> list[str]:
    """Problems of the committed vendor folder against VENDORED.json (empty: all good)."""
    record = json.loads((VENDOR / "VENDORED.json").read_text())
    problems = []
    for name, (version, _folder, files, _use) in PACKAGES.items():
        p = record["packages"].get(name)
        if p is None or p["version"] != version:
            problems.append(f"{name}: VENDORED.json does not record version {version}")
            continue
        if len(p["files"]) != len(files):
            problems.append(f"{name}: {len(p['files'])} files recorded, {len(files)} pinned")
        for rel, digest in p["files"].items():
            f = VENDOR / rel
            if not f.is_file():
                problems.append(f"{rel}: missing")
            elif _sha256(f) != digest:
                problems.append(f"{rel}: sha256 differs from VENDORED.json")
    return problems


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="verify, do not download")
    args = ap.parse_args()
    if args.check:
        problems = check()
        print("\n".join(problems) or "vendored files match VENDORED.json")
        sys.exit(1 if problems else 0)
    rec = vendor()
    for name, p in rec["packages"].items():
        print(f"{name} {p['version']} ({p['license']}): {len(p['files'])} files")


if __name__ == "__main__":
    main()
