# Two entry points for a fresh machine: `make test` and `make demo`.
# Both create .venv and install the package into it; nothing is installed by hand.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: test demo venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test]'
	touch $(STAMP)

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python tools/demo.py demo-output

clean:
	rm -rf $(VENV) demo-output .pytest_cache
