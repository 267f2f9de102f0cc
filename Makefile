# The two commands a new user needs: `make demo` and `make test`.
# Both create .venv and install hiyari (editable) with everything it needs when missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT ?= out

.PHONY: demo test test-unit test-baseline-dispatch docs lint bench install clean browser

# The editable install's finder comes after Python's path finder, so a folder named hiyari
# beside a script (the clone itself, for a script in its parent) would shadow the package as a
# namespace package. This .pth runs after setuptools' and puts hiyari's finder first.
EDITABLE_FIRST := 'import sys; sys.meta_path.sort(key=lambda f: not getattr(f, "__module__", "").startswith("__editable___hiyari_"))'

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	printf '%s\n' $(EDITABLE_FIRST) > "$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/hiyari_editable_first.pth"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/hiyari demo --out $(OUT)/demo

# Debian's chromium (about 480 MB with its dependencies) for the replay's browser test; never
# Playwright's own browser download. Needs root or sudo; `make test SKIP_BROWSER=1` skips it
# (the browser test is then reported as skipped).
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
browser:
ifeq ($(SKIP_BROWSER),1)
	@echo "SKIP_BROWSER=1: not installing chromium; the replay browser test will be skipped"
else
	@command -v chromium >/dev/null || { \
	  echo "installing Debian's chromium for the replay browser test (apt-get, ~480 MB)"; \
	  $(SUDO) apt-get update && $(SUDO) apt-get install -y chromium; }
endif

# The suite runs on TEST_WORKERS pytest-xdist workers (the two cores of a developer machine
# and CI); `make test TEST_WORKERS=0` runs it in one process, for debugging.
TEST_WORKERS ?= 2
# The kernels are compiled once, one process per core, before the workers start: on a fresh
# clone the workers and the runs they start would otherwise all compile the same kernels at once.
test: $(STAMP) browser
	$(BIN)/ruff check .
	$(BIN)/python tests/support/warm_kernels.py
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS)

# The unit tests alone (tests/unit: no SUMO run), for a quick check while editing.
test-unit: $(STAMP)
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) -m "not e2e"

# The compiled-kernel tests again with numpy's SIMD dispatch limited to its baseline: numpy's
# vectorised sin / cos / pow differ between CPUs in the last bits, and both paths must pass
# wherever the suite runs (CI runs this after `make test`).
NUMPY_BASELINE_ONLY := X86_V3 X86_V4 AVX512_ICL AVX512_SPR AVX512_SKX AVX512F AVX2 FMA3
test-baseline-dispatch: $(STAMP)
	NPY_DISABLE_CPU_FEATURES="$(NUMPY_BASELINE_ONLY)" $(BIN)/python -m pytest -q -n $(TEST_WORKERS) -m kernels

# The user guide (docs/) as a static site in site/.
docs: $(STAMP)
	$(BIN)/mkdocs build --strict --quiet

lint: $(STAMP)
	$(BIN)/ruff check . && $(BIN)/ruff format --check .

bench: $(STAMP)
	for b in benchmarks/*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache
