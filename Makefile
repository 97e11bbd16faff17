# fm2uav — the two commands: `make run` and `make test` (fresh machine → working).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
OUT    ?= out

.PHONY: run test bench install clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	@touch $(STAMP)

install: $(STAMP)

## make run: plan the default mission on the built-in open-field scenario
run: $(STAMP)
	$(VENV)/bin/fm2uav plan --scenario open-field --out $(OUT)/plan --force
	@echo "outputs written to $(OUT)/plan/ (path.csv, plan.png, summary.json)"

## make test: the whole suite
test: $(STAMP)
	$(VENV)/bin/pytest -q

## make bench: speed and memory against peers (writes benchmarks/results/*.json)
bench: $(STAMP)
	$(PY) benchmarks/run.py

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache benchmarks/results
