"""The tests mirror ``src/fm2uav`` (tests/README.md): a test module outside the mirror fails here.

The tests of ``src/fm2uav/<package>/<module>.py`` live in
``tests/<package>/test_<module>[_<aspect>].py``; the package's own ``__init__.py`` is
``test_init``. The only folders that mirror no package are ``E2E_FOLDERS``.
"""

from __future__ import annotations

from pathlib import Path

TESTS = Path(__file__).resolve().parent
SRC = TESTS.parent / "src" / "fm2uav"

#: folders of tests/ that mirror no package of src/fm2uav (documented in tests/README.md):
#: cross-command end-to-end runs, and checks of the repository outside src/
E2E_FOLDERS = ("e2e", "repo")
#: test modules at the top of tests/ that test no module: this file
TOP_EXTRAS = ("test_layout.py",)


def _folders() -> list[Path]:
    """Every folder of tests/ holding Python files (tests/ itself included)."""
    return sorted({p.parent for p in TESTS.rglob("*.py") if "__pycache__" not in p.parts})


def _mirror(folder: Path) -> Path:
    return SRC.joinpath(*folder.relative_to(TESTS).parts)


def _is_e2e(folder: Path) -> bool:
    rel = folder.relative_to(TESTS).parts
    return bool(rel) and rel[0] in E2E_FOLDERS


def _module_names(package: Path) -> set[str]:
    """The names a test module may start with: the package's modules and subpackages
    (without a leading underscore) and ``init`` for its ``__init__.py``."""
    names = {"init"}
    for p in package.iterdir():
        if p.suffix == ".py" and p.stem != "__init__":
            names.add(p.stem.strip("_"))  # __main__.py -> test_main.py
        elif p.is_dir() and (p / "__init__.py").exists():
            names.add(p.name)
    return names


def test_every_test_folder_mirrors_a_package_or_is_an_e2e_folder():
    stray = [str(f.relative_to(TESTS)) for f in _folders()
             if not _is_e2e(f) and not (_mirror(f) / "__init__.py").exists()]
    assert not stray, (f"test folders without a package src/fm2uav/<same path>: {stray}; "
                       f"move them to the mirror of the module they test (tests/README.md), "
                       f"or to tests/{E2E_FOLDERS[0]}/ if they run several commands end to end")


def test_every_test_module_is_named_after_a_module_of_its_package():
    stray = []
    for folder in _folders():
        if _is_e2e(folder) or not (_mirror(folder) / "__init__.py").exists():
            continue  # e2e folders take any name; stray folders fail the test above
        names = _module_names(_mirror(folder))
        for f in sorted(folder.glob("test_*.py")):
            if folder == TESTS and f.name in TOP_EXTRAS:
                continue
            rest = f.stem[len("test_"):]
            if not any(rest == n or rest.startswith(n + "_") for n in names):
                stray.append(str(f.relative_to(TESTS)))
    assert not stray, (f"test modules not named test_<module>[_<aspect>] after a module of "
                       f"the package they mirror: {stray} (tests/README.md)")


def test_every_test_folder_is_a_package():
    # same-named modules in different folders (experiments/test_city.py and
    # scenarios/test_city.py) need the __init__.py, and so do the relative helper imports
    missing = [str(f.relative_to(TESTS)) for f in _folders() if not (f / "__init__.py").exists()]
    assert not missing, f"test folders without __init__.py: {missing}"


def test_the_mirror_rule_is_checked_on_real_folders():
    # the checks above would pass vacuously if the paths were wrong
    assert (SRC / "__init__.py").exists()
    assert _mirror(TESTS / "missions" / "coverage") == SRC / "missions" / "coverage"
    assert {"fmm", "sources", "velocity", "init"} <= _module_names(SRC / "eikonal")
    assert len(_folders()) > 10
