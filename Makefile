# fm2uav — the two commands: `make run` and `make test` (fresh machine → working).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
OUT    ?= out
## pytest-xdist workers for make test / test-fast (auto: one per core; WORKERS=0 runs serially)
WORKERS ?= auto
XDIST  := -n $(WORKERS) --dist loadfile
## the test modules' assertion-rewritten bytecode is kept (__pycache__, git-ignored) even
## where the environment sets PYTHONDONTWRITEBYTECODE: rewriting them costs each worker ~7 s
PYTEST := PYTHONDONTWRITEBYTECODE= $(VENV)/bin/pytest

.PHONY: run test test-fast bench install clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	@## the package's bytecode, written even where PYTHONDONTWRITEBYTECODE is set (an editable
	@## install has none, and every command would compile its modules again: +0.1 s a --help)
	$(PY) -m compileall -q src
	@echo "compiling the numba kernels once (cached for every later run) ..."
	$(PY) -m fm2uav.planning.warmup
	@## the layers above planning warm their own kernels (planning cannot import them)
	$(PY) -m fm2uav.vehicles.warmup
	$(PY) -m fm2uav.baselines.warmup
	$(PY) -m fm2uav.missions.warmup
	$(PY) -m fm2uav.autopilot.warmup
	$(PY) -m fm2uav.analysis.warmup
	@## every help page rendered once and kept (fm2uav._help_cache): the next `fm2uav <cmd>
	@## --help` from a script or a pipe copies it without typer or rich (best effort)
	-@$(PY) -c "from fm2uav.cli import COMMANDS, REPRODUCE; print('', *COMMANDS, 'reproduce', *('reproduce ' + c for c in REPRODUCE), sep='\n')" \
		| while read -r words; do $(VENV)/bin/fm2uav $$words --help >/dev/null 2>&1 </dev/null || true; done
	@touch $(STAMP)

## make install: the venv with the package (editable) and its numba kernels compiled
install: $(STAMP)

## make run: the default mission — terrain-following flight (150 m above ground, the
## TFF paper's case 3) over the built-in open-field scenario, with ground-control
## exports and an interactive report, in $(OUT)/default_mission/: a folder of its own, not the
## default folder of any mission file (`fm2uav run mission.yaml` writes out/mission/, `fm2uav run
## examples/open_field_tff.yaml` out/open_field_tff/), so --force replaces nothing of yours
run: $(STAMP)
	$(VENV)/bin/fm2uav run examples/open_field_tff.yaml --out $(OUT)/default_mission --force
	@echo ""
	@echo "outputs written to $(OUT)/default_mission/ — open $(OUT)/default_mission/report.html in a browser;"
	@echo "mission.plan loads in QGroundControl, mission.waypoints is a MAVLink WPL 110 file"

## make test: the layer contract (import-linter, [tool.importlinter] in pyproject.toml),
## then the whole suite, in parallel (pytest-xdist: one file's tests in one worker, and the
## files sharing cli_once's runs in one worker too, tests/conftest.py); the 15 slowest tests
## are listed at the end (what to split when the suite grows)
test: $(STAMP)
	$(VENV)/bin/lint-imports
	$(PYTEST) -q $(XDIST) --durations=15

## make test-fast: for development — the same suite without the tests marked `slow`
## (long end-to-end runs: reproductions, sweeps, CLI missions); `make test` runs them too
test-fast: $(STAMP)
	$(VENV)/bin/lint-imports
	$(PYTEST) -q $(XDIST) -m "not slow"

## make bench: speed and memory against peers (writes benchmarks/results/bench.json, the
## table in docs/performance.md and the summary in README.md)
bench: $(STAMP)
	$(PY) -m benchmarks.run

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache benchmarks/results
