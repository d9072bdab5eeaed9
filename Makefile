# `make demo` and `make test` are all a fresh clone needs: each creates .venv from
# pyproject.toml when it is missing (or older than pyproject.toml), then runs.
VENV := .venv
PYTHON := $(VENV)/bin/python
STAMP := $(VENV)/.installed
DEMO_DIR := outputs/demo

.PHONY: demo test clean

$(STAMP): pyproject.toml
	test -x $(PYTHON) || python3 -m venv $(VENV)
	$(PYTHON) -m pip install --quiet --upgrade pip
	$(PYTHON) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/pbp-drake study diagrams/toy_alpha_study.yaml --output $(DEMO_DIR)
	$(VENV)/bin/pbp-drake run diagrams/toy_alpha_study.yaml --scene scene_1 \
		--method pbp_alternated --headless --record $(DEMO_DIR)/replay.html

test: $(STAMP)
	$(PYTHON) -m pytest

clean:
	rm -rf $(VENV) outputs build *.egg-info
