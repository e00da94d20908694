# davis-ag: every target sets itself up; the virtual environment is made on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
DOCS_STAMP := $(VENV)/.docs-installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
OUT ?= out

.PHONY: setup demo test lint docs bench reproduce clean

setup: $(STAMP)

# torch first, pinned: 2.13.0 is a CPU build already on this machine's disk, where an open
# range would download a multi-GB CUDA build. PyPI's torchvision 0.28.0 is a CUDA build whose
# compiled operators do not load beside it: docs/detection.md ("torchvision on a CPU-only torch")
# says what works (PyTorch's CPU index where reachable, else prepare_ultralytics()).
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q torch==2.13.0
	$(BIN)/python -m pip install -q -e ".[test,ray,detect,robot,contrib,worlds]"
	rm -f $(VENV)/.installed-*
	touch $@

demo: $(STAMP)
	$(BIN)/davis-ag demo --out $(OUT)/demo

# One pytest worker per core (pytest-xdist); a test file stays on one worker, so its module
# fixtures (a generated dataset, a trained model) are made once.
test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist loadfile

# ruff (pyflakes, pycodestyle, bugbear, import order, pyupgrade, RUF, and the formatter's check)
# over the code and tests, mypy over src/ (settings in pyproject.toml). `ruff format src tests` makes the format check pass.
lint: $(STAMP)
	$(BIN)/ruff check src tests
	$(BIN)/ruff format --check src tests
	$(BIN)/mypy src

# The documentation site from docs/ and the docstrings (mkdocs.yml) into out/site. --strict: a
# broken link or anchor, or a docstring mkdocstrings cannot read, fails it. Its tools (the `docs`
# extra) go on top of the setup above, which pins torch first, so `make test` does without them.
$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q -e ".[docs]"
	rm -f $(VENV)/.docs-installed-*
	touch $@

docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

bench: $(STAMP)
	$(BIN)/davis-ag bench --out $(OUT)/bench.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only crops --out $(OUT)/bench-crops.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only verify --out $(OUT)/bench-verify.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only play --out $(OUT)/bench-play.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only robot --out $(OUT)/bench-robot.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only mapping --out $(OUT)/bench-mapping.json --doc docs/performance.md
	$(BIN)/davis-ag bench --only sharing --out $(OUT)/bench-sharing.json --doc docs/performance.md

reproduce: $(STAMP)
	$(BIN)/davis-ag reproduce --out $(OUT)/reproduce

clean:
	rm -rf $(OUT) .pytest_cache
