"""docs/architecture.md lists the same layer order as the import-linter contract."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _contract_layers() -> list[str]:
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    layers = next(c for c in cfg["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    return [name.strip("()") for name in layers["layers"]]


def _doc_layers() -> list[str]:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (`[^|]+`) \|", text.split("## Layers, one way")[1].split("\n## ")[0],
                      flags=re.M)
    names = []
    for cell in rows:
        names += [n.rstrip("/") for n in re.findall(r"`([^`]+)`", cell)]
    return names


def test_doc_layer_table_matches_the_contract_bottom_to_top():
    assert _doc_layers() == list(reversed(_contract_layers()))


def test_every_top_level_module_is_a_layer():
    pkg = ROOT / "src" / "fm2uav"
    found = {p.stem for p in pkg.glob("*.py") if p.stem != "__init__"}
    found |= {p.name for p in pkg.iterdir() if (p / "__init__.py").exists()}
    assert found <= set(_contract_layers()), sorted(found - set(_contract_layers()))
