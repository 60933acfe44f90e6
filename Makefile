# Two commands: `make run` writes every scene's tables and figures into out/;
# `make test` runs the test-suite (`make docs` builds the documentation into docs/_build/html).
# All create the virtual environment $(VENV) and
# install mbsuite into it in editable mode (again whenever pyproject.toml changes).

PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.mbsuite-installed
OUT    ?= out

export MPLBACKEND := Agg

.PHONY: run test bench docs clean

run: $(STAMP)
	$(BIN)/mbsuite run --all -o $(OUT)/

test: $(STAMP)
	$(BIN)/python -m pytest -q

# warnings are errors; the gallery runs examples/ in fast mode (docs/conf.py sets MBSUITE_MODE=fast)
docs: $(STAMP)
	$(BIN)/python -m sphinx -W --keep-going -b html docs docs/_build/html

bench: $(STAMP)
	@if [ -f benchmarks/run_all.py ]; then \
		$(BIN)/python benchmarks/run_all.py; \
	else \
		echo "benchmarks/run_all.py does not exist yet; run single benchmarks with $(BIN)/python benchmarks/<name>.py"; \
	fi

$(BIN)/python:
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), f"mbsuite needs Python >= 3.11, $(PYTHON) is {sys.version.split()[0]}"'
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test,docs]'
	touch $@

clean:
	rm -rf $(OUT) .pytest_cache .hypothesis build dist docs/_build docs/generated docs/auto_examples
	# numba's on-disk cache: a cached kernel is not recompiled when a kernel it calls changes
	find core railway biomech coaster tests examples -name '*.nb[ic]' -delete
