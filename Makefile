# bearing_lab: the two commands a newcomer needs are `make validate` and `make test`.
# Both create .venv and install the package (with test extras) on first use.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: install lock validate test docs bench bench-quick study verdicts clean

install: $(STAMP)

# the locked versions (constraints.txt) the suite is tested with; `make lock` refreshes them.
# The docs extra is installed too: the test suite builds the API reference (tests/test_api_docs.py).
$(STAMP): pyproject.toml constraints.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -c constraints.txt pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[test,docs]"
	touch $(STAMP)

# re-resolve the newest versions pip finds today into constraints.txt (then run `make test`)
lock:
	rm -rf .lock-venv && $(PYTHON) -m venv .lock-venv
	.lock-venv/bin/python -m pip install --quiet --upgrade pip
	.lock-venv/bin/python -m pip install --quiet -e ".[test,docs]"
	{ sed -n '1,3p' constraints.txt; .lock-venv/bin/python -m pip freeze --all --exclude-editable \
	    | grep -v -i -e '^bearing.lab' -e '^setuptools=' -e '^wheel='; } > constraints.txt.new
	mv constraints.txt.new constraints.txt && rm -rf .lock-venv

validate: install
	$(VENV)/bin/bearing-lab validate -o reports

# one file per worker, handed out in the order tests/conftest.py sets (the longest first)
test: install
	$(PY) -m pytest -n 2 --dist loadfile --no-loadscope-reorder -q $(PYTEST_ARGS)

# the API reference from the docstrings, and the docs/*.md pages, as HTML in docs/_build/html
# (git-ignored); any Sphinx warning fails the build
docs: install
	$(PY) -m sphinx -b html -W --keep-going -q docs docs/_build/html
	@echo "open docs/_build/html/api/index.html"

# every benchmark figure the docs quote, regenerated into benchmarks/results/ (hours; the work-precision
# study, `bearing-lab bench`, is one entry); `bench-quick` runs each script's smallest mode, to check the
# runner only (its files say "quick: figures not for quoting": do not commit them).  MIRROR: the data folder.
bench: install
	$(PY) benchmarks/run_all.py $(if $(MIRROR),--mirror $(MIRROR))

bench-quick: install
	$(PY) benchmarks/run_all.py --quick $(if $(MIRROR),--mirror $(MIRROR))

study: install
	$(VENV)/bin/bearing-lab study paper

# every shipped case's row verdicts and margins (benchmarks/verdicts.csv, compared by the tests)
verdicts: install
	$(PY) benchmarks/verdicts.py table

clean:
	rm -rf $(VENV) reports/* .pytest_cache
