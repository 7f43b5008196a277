# bearing_lab: the two commands a newcomer needs are `make validate` and `make test`.
# Both create .venv and install the package (with test extras) on first use.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: install validate test bench study clean

install: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	touch $(STAMP)

validate: install
	$(VENV)/bin/bearing-lab validate -o reports

test: install
	$(PY) -m pytest -n 2 --dist loadfile -q $(PYTEST_ARGS)

bench: install
	$(VENV)/bin/bearing-lab bench

study: install
	$(VENV)/bin/bearing-lab study paper

clean:
	rm -rf $(VENV) reports/* .pytest_cache
