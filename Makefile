# `make demo` and `make test` are all a fresh clone needs: each creates .venv from
# pyproject.toml when it is missing (or older than pyproject.toml), then runs.
# .venv holds the oldest Drake pyproject.toml allows (.ci/oldest.txt pins it) on `python3`
# (3.11 on CI); `make test-newest` tests the newest Drake pip gives on Python 3.12, in
# .venv-newest.
VENV := .venv
PYTHON := $(VENV)/bin/python
STAMP := $(VENV)/.installed
OLDEST := .ci/oldest.txt
NEWEST_VENV := .venv-newest
NEWEST_STAMP := $(NEWEST_VENV)/.installed
# pyenv's 3.12 when there is one (its shim answers only where pyenv selects it), else the
# system's (Ubuntu 24.04's python3.12).
PYTHON312 ?= $(firstword $(wildcard $(HOME)/.pyenv/versions/3.12*/bin/python3.12) python3.12)
DEMO_DIR := outputs/demo
# $(call with_bytecode_cache,VENV): the many Python processes of the tests and the jobs
# (workers, commands, study workers, kernels) keep their compiled bytecode under
# VENV/pycache, the source tree free of __pycache__; a PYTHONDONTWRITEBYTECODE in the
# environment would have each of them compile the package (and the tests) anew. pip runs
# with it too: the bytecode it compiles as it installs lands there, where the processes
# look, and the first ones of a fresh venv do not compile the dependencies again at once.
with_bytecode_cache = env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX="$(CURDIR)/$(1)/pycache"
# How the targets below run the venvs' programs: each with its bytecode cache.
IN_VENV := $(call with_bytecode_cache,$(VENV))
NEWEST_IN_VENV := $(call with_bytecode_cache,$(NEWEST_VENV))

.PHONY: demo lint test test-newest test-fast chromium graphviz tutorials diagrams bench soak \
	results docs clean

$(STAMP): pyproject.toml $(OLDEST)
	test -x $(PYTHON) || python3 -m venv $(VENV)
	$(IN_VENV) $(PYTHON) -m pip install --quiet --upgrade pip
	$(IN_VENV) $(PYTHON) -m pip install --quiet --constraint $(OLDEST) -e '.[test]'
	touch $(STAMP)

# The newest of everything pip gives Python 3.12 (`--upgrade-strategy eager`), made afresh
# when pyproject.toml changes (`rm -r .venv-newest` to take a later Drake).
$(NEWEST_STAMP): pyproject.toml
	test -x $(NEWEST_VENV)/bin/python || $(PYTHON312) -m venv $(NEWEST_VENV)
	$(NEWEST_IN_VENV) $(NEWEST_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(NEWEST_IN_VENV) $(NEWEST_VENV)/bin/python -m pip install --quiet --upgrade \
		--upgrade-strategy eager -e '.[test]'
	touch $(NEWEST_STAMP)

# The HSR reaching task with PBP-Alt and the virtual participant, then the 2-D alpha study.
demo: $(STAMP)
	$(IN_VENV) $(VENV)/bin/pbp-drake run diagrams/hsr_reach.yaml --method pbp_alternated \
		--operator virtual --headless --record $(DEMO_DIR)/hsr_reach.html --force
	$(IN_VENV) $(VENV)/bin/pbp-drake study diagrams/toy_alpha_study.yaml --output $(DEMO_DIR)
	$(IN_VENV) $(VENV)/bin/pbp-drake run diagrams/toy_alpha_study.yaml --scene scene_1 \
		--method pbp_alternated --headless --record $(DEMO_DIR)/replay.html --force
	@echo "Open $(DEMO_DIR)/hsr_reach.html in a browser to replay the HSR task."

# $(call debian_tool,COMMAND,PACKAGE,PURPOSE): some tests need a Debian program (never a
# download of its own): install PACKAGE when COMMAND is missing and apt-get is usable as
# root; otherwise say so and go on (those tests skip). Under CI a failed install is an error.
define debian_tool
	@if command -v $(1) >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		echo "Installing Debian's $(2) for $(3)"; \
		{ apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
			apt-get install -y -qq $(2) >/dev/null; } </dev/null \
		|| { echo "note: installing $(2) failed (an error under CI; elsewhere $(3) skip)"; \
		     [ -z "$${CI:-}" ]; }; \
	else \
		echo "note: $(1) is missing (installing it needs root and apt-get); $(3) will skip"; \
	fi
endef

# The headless browser tests drive Debian's `chromium` (never `playwright install`).
chromium:
	$(call debian_tool,chromium,chromium,the browser tests)

# Graphviz's `dot` draws the system diagrams (`pbp-drake draw`): the tests compare the
# drawings in diagrams/ with what it draws now.
graphviz:
	$(call debian_tool,dot,graphviz,the drawing tests)

# Ruff's checks ([tool.ruff] in pyproject.toml) on the package, tests, docs and notebooks.
lint: $(STAMP)
	$(PYTHON) -m ruff check .

# The whole suite after the lint, in two runs at once (tests/run_suite.py): the browser tests
# (Chromium, real-time pages) one at a time, and the others in two processes at the lowest
# priority, so that they take only the CPU the pages leave and a page is never starved.
test: lint chromium graphviz
	$(IN_VENV) $(PYTHON) tests/run_suite.py

# The suite but the browser tests on Python 3.12 with the newest Drake and NumPy (.ci/run
# runs it after `make test`): what a user of a newer Python gets from pip.
test-newest: $(NEWEST_STAMP) graphviz
	$(NEWEST_IN_VENV) $(NEWEST_VENV)/bin/python -m pytest \
		-m "not browser" -n 2 --dist worksteal

# Everything but the tests marked slow, in two processes (pytest-xdist): a developer's run.
test-fast: $(STAMP) graphviz
	$(IN_VENV) $(PYTHON) -m pytest -m "not slow" -n 2 --dist worksteal

# The tutorial notebooks (tutorials/*.ipynb) in Jupyter, in the project's venv.
$(VENV)/.installed-tutorials: $(STAMP)
	$(IN_VENV) $(PYTHON) -m pip install --quiet -e '.[test,tutorials]'
	touch $@

tutorials: $(VENV)/.installed-tutorials graphviz
	$(IN_VENV) $(VENV)/bin/jupyter lab tutorials

# Redraw every scenario's system diagram beside its YAML (diagrams/*.svg).
diagrams: $(STAMP) graphviz
	$(IN_VENV) $(PYTHON) -m pbp_drake.draw diagrams/*.yaml

# `pbp-drake bench`: the DMP bank against pydmps and movement_primitives, the closed-loop HSR
# speed and the control-rate figure, into outputs/bench (bench.json, bench_control_rate.png);
# fails (exit code 1) when one of its checks fails.
$(VENV)/.installed-bench: $(STAMP)
	$(IN_VENV) $(PYTHON) -m pip install --quiet -e '.[test,bench]'
	touch $@

bench: $(VENV)/.installed-bench
	$(IN_VENV) $(PYTHON) -m pbp_drake_bench

# An hour of simulated time of the HSR reaching task with Meshcat on, runs back to back in
# one process; fails when memory grows 10 % or more after the first minute (about 15
# minutes of wall time on an idle 2-core machine, 25 on a shared one).
soak: $(STAMP)
	$(IN_VENV) $(PYTHON) -m pbp_drake_bench.soak --minutes 60

# Every study the docs quote (the list: pbp_drake_bench/results_catalogue.py), each with
# --jobs 2 into outputs/results/NAME, and its table into docs/results/generated/NAME.md
# (`pbp-drake report DIR --markdown FILE`, whose first line is the command that made it).
# From scratch, about an hour on a 2-core machine. Run again after an interruption, it
# resumes from the trials today's code made; a study folder other code made starts afresh.
results: $(STAMP)
	$(IN_VENV) $(PYTHON) -m pbp_drake_bench.results_catalogue

# The documentation site (Sphinx, MyST, furo) into docs/_build/html; any warning fails.
$(VENV)/.installed-docs: $(STAMP)
	$(IN_VENV) $(PYTHON) -m pip install --quiet -e '.[test,docs]'
	touch $@

docs: $(VENV)/.installed-docs
	$(IN_VENV) $(PYTHON) -m sphinx -W --keep-going -b html docs docs/_build/html

clean:
	rm -rf $(VENV) $(NEWEST_VENV) outputs build *.egg-info docs/_build
