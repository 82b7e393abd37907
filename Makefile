# aeroservo: the two set-up commands are `make demo` and `make test` (README).
# Each creates its own virtual environment in .venv (override with VENV=...).

PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install demo test test-fast lint bench bench-quick clean

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	$(BIN)/python -m compileall -q src
	touch $(STAMP)

demo: install
	mkdir -p out
	$(BIN)/aeroservo flutter goland --pk --plot out/goland_vg.png
	$(BIN)/aeroservo flutter scenarios/goland_aileron.toml --json > out/goland_aileron_flutter.json
	$(BIN)/aeroservo simulate scenarios/goland_aileron_lqg.toml --out out
	@echo "wrote out/goland_vg.png, out/goland_aileron_flutter.json and out/goland_aileron_lqg.*"

lint: install
	$(BIN)/ruff check src tests bench
	$(BIN)/ruff format --check src tests bench

# two workers (the 2-core machine the suite is budgeted on), one module per worker at a time
# (module fixtures built once), one BLAS thread each (no oversubscription)
test: lint
	OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 \
		$(BIN)/python -m pytest -n 2 --dist loadscope

# everyday work, under 2 minutes on the 2-core machine: every test module, without the tests
# marked slow (over about 2 s each, or sharing a module fixture that is); `make test` runs all
test-fast: install
	OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 \
		$(BIN)/python -m pytest -n 2 --dist loadscope -m "not slow"

# every target of the performance issues with its ratio to a same-run baseline and PASS/FAIL
bench: install
	$(BIN)/python bench/bench_startup.py
	$(BIN)/python bench/bench_flutter.py
	$(BIN)/python bench/bench_statespace.py
	$(BIN)/python bench/bench_control.py
	$(BIN)/python bench/bench_mpc.py
	$(BIN)/python bench/bench_mpc_step.py
	$(BIN)/python bench/bench_trade.py
	$(BIN)/python bench/bench_gust_loads.py
	$(BIN)/python bench/bench_lco.py
	$(BIN)/python bench/bench_dlm.py

# a few minutes: the issue-17 targets with fewer repeats (CI runs it as a smoke test that
# reports and does not gate on timing: tests/test_bench.py)
bench-quick: install
	$(BIN)/python bench/bench_startup.py --quick
	$(BIN)/python bench/bench_flutter.py --quick
	$(BIN)/python bench/bench_mpc_step.py --quick
	$(BIN)/python bench/bench_trade.py --quick
	$(BIN)/python bench/bench_dlm.py --quick

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache
