# The two commands of the README: `make demo` and `make test`. Both set everything up first.
VENV ?= .venv
PY := $(VENV)/bin/python
HIPER := $(VENV)/bin/hiper

.PHONY: setup demo test lint bench clean

setup:
	@VENV=$(VENV) bash scripts/setup.sh

demo: setup
	@bash scripts/demo.sh $(VENV)

test: setup lint
	$(PY) -m pytest -q

lint:
	$(VENV)/bin/ruff check hiper_cli tests
	$(VENV)/bin/mypy

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache demo.hiper
