# Two commands: `make run` and `make test`. Both create .venv if needed.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: venv run test browser docs bench bench-containment bench-flagship corpus clean

venv: $(STAMP)

# After installing, one step of the flagship case compiles its kernels into the cache
# (~/.cache/wovenimpact/numba, once per install or kernel change; its time:
# docs/performance.md), so that `make run` reaches its first step within seconds.
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	@echo "make: compiling the kernels once (a few minutes; cached afterwards)"
	$(BIN)/wovenimpact run examples/plate_impact/plies4_120.toml --out $(VENV)/warm-up \
	    --set 'run.end_time=0.5 us' > $(VENV)/warm-up.log 2>&1
	touch $(STAMP)

# Flagship example: 4 Kevlar plies struck at 120 m/s (thesis ch. 7; its time: docs/performance.md),
# and the single-element report of the crossover model.
run: venv
	$(BIN)/wovenimpact run examples/plate_impact/plies4_120.toml --out out/plies4_120
	$(BIN)/wovenimpact element-test uniaxial --material examples/materials/kevlar_thesis.toml --out out/element_uniaxial
	$(BIN)/wovenimpact element-test biaxial --material examples/materials/kevlar_thesis.toml --out out/element_biaxial
	$(BIN)/wovenimpact element-test picture-frame --material examples/materials/kevlar_thesis.toml --out out/element_picture_frame
	@echo "Element tests: out/element_*/history.csv and out/element_*/*.png"
	@echo "Flagship: out/plies4_120/ (summary.json, history.csv, plots/, fields/fields.pvd for ParaView)"
	@echo "Report: out/plies4_120/report.html"

# One pytest worker per core (pytest-xdist): on a fresh clone most of the suite's time is Numba
# compiling the kernels into the cache, which two workers share; the slowest tests are listed.
# The browser test (tests/io/test_report_browser.py) opens a report.html in headless Chromium:
# run as root with apt-get (as CI is), `make test` first installs Debian's chromium-headless-shell
# if no Chromium is on the PATH (~100 MB, ~20 s, once); elsewhere that test is skipped.
test: venv browser
	$(BIN)/python -m pytest -q -n auto --durations=15

browser:
	@if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-headless-shell >/dev/null 2>&1 \
	    && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "make: installing chromium-headless-shell (Debian) for the browser test"; \
	  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	      --no-install-recommends chromium-headless-shell >/dev/null; } \
	  || echo "make: chromium-headless-shell not installed: the browser test will be skipped"; \
	fi

# docs/case_keys.md, the key reference generated from the input schemas (a test checks it is
# current).
docs: venv
	$(BIN)/python -m wovenimpact.spec.reference --write docs/case_keys.md

# The machine line first; then the fabric kernel alone, the explicit step (the same as
# `wovenimpact bench`) and the ply-on-ply contact; their figures (out/bench/*.json) rewrite
# the `make bench` section of docs/performance.md.
bench: venv
	$(BIN)/python -c "from wovenimpact.benchmark import machine_line; print(machine_line())"
	$(BIN)/python benchmarks/bench_fabric_kernel.py --save=out/bench/fabric_kernel.json
	$(BIN)/python benchmarks/bench_shell.py --no-machine-line --save=out/bench/shell.json
	$(BIN)/python benchmarks/bench_contact.py --save=out/bench/contact.json
	$(BIN)/python benchmarks/performance_page.py

# Issue 11's end-to-end figure: the 10-ply hybrid casing at ~55 k elements (5.5 mm, the graded ring) to
# the end of the event (the case stops once its outcome is decided; 4 ms at most) on all cores,
# against the 3-minute target (about 7 minutes here; not in `make bench`).
bench-containment: venv
	$(BIN)/python benchmarks/bench_containment.py --save=out/bench/containment.json
	$(BIN)/python benchmarks/performance_page.py

# The flagship `make run` case timed as the containment benchmark is (cached compilation,
# no field frames or checkpoints); rewrites the flagship section of docs/performance.md.
bench-flagship: venv
	$(BIN)/python benchmarks/bench_containment.py --case=examples/plate_impact/plies4_120.toml \
		--size=0.94mm --end=0.25ms --save=out/bench/flagship.json
	$(BIN)/python benchmarks/performance_page.py

# The acceptance corpus of issue 12: ~430 bad inputs written from the examples into
# out/corpus and run in process; prints clean / traceback / hang / nonsense counts
# (out/corpus/results.csv) and fails unless every item is clean. Minutes, not seconds.
corpus: venv
	$(BIN)/python -m tests.corpus.runner --dir out/corpus

clean:
	rm -rf out .pytest_cache
