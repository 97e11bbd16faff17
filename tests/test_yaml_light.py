"""fm2uav._yaml_light: yaml's reader gets a pattern that compiles fast and matches the same."""

from __future__ import annotations

import json
import re
import subprocess
import sys

from fm2uav import _yaml_light
from fm2uav._yaml_light import NOT_ALLOWED, YAML_NON_PRINTABLE


def test_the_fast_pattern_matches_exactly_the_characters_yaml_s_does():
    slow, fast = re.compile(YAML_NON_PRINTABLE), re.compile(NOT_ALLOWED)
    text = "".join(map(chr, range(sys.maxunicode + 1)))  # every code point
    assert [m.start() for m in slow.finditer(text)] == [m.start() for m in fast.finditer(text)]
    assert len(fast.findall(text)) == 9 + 2 + 18 + 6 + 26 + 2048 + 2  # not a vacuous pass


PROBE = """
import json, sys
from fm2uav._yaml_light import import_yaml
yaml = import_yaml()
from fm2uav._validate import load_yaml
try:
    load_yaml({text!r}, "mission file", source="m.yaml")
except Exception as exc:
    message = str(exc)
print(json.dumps([yaml.reader.Reader.NON_PRINTABLE.pattern, message]))
"""


def _probe(text: str, fast: bool) -> list[str]:
    code = PROBE.format(text=text)
    if not fast:  # yaml imported first: its own pattern
        code = "import yaml\n" + code
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_a_fresh_import_compiles_the_fast_pattern_and_errors_are_unchanged():
    text = "world: {scenario: open-field}\nname: a\x07b\n"
    fast_pattern, fast_message = _probe(text, fast=True)
    slow_pattern, slow_message = _probe(text, fast=False)
    assert slow_pattern == YAML_NON_PRINTABLE  # the constant is PyYAML's own pattern
    assert fast_pattern == NOT_ALLOWED
    assert fast_message == slow_message
    assert "#x0007" in fast_message and "special characters are not allowed" in fast_message


def test_nothing_is_seeded_without_re_s_cache(monkeypatch):
    monkeypatch.setattr(re, "_cache", None, raising=False)
    assert _yaml_light._seed() is False
