# Two commands: `make run` and `make test`. Both create .venv if needed.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: venv run test bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# Flagship example of the day: a Kevlar ply struck at its centre (shell solver), and the
# single-element report of the crossover model.
run: venv
	$(BIN)/wovenimpact run examples/cases/fabric_plate_impulse.toml --out out/fabric_plate_impulse
	$(BIN)/wovenimpact element-test uniaxial --material examples/materials/kevlar_thesis.toml --out out/element_uniaxial
	$(BIN)/wovenimpact element-test biaxial --material examples/materials/kevlar_thesis.toml --out out/element_biaxial
	$(BIN)/wovenimpact element-test picture-frame --material examples/materials/kevlar_thesis.toml --out out/element_picture_frame
	@echo "Report: out/fabric_plate_impulse/ (summary.json, history.csv, plots/, fields/fields.pvd for ParaView)"
	@echo "        out/element_*/history.csv and out/element_*/*.png"

test: venv
	$(BIN)/python -m pytest -q

bench: venv
	$(BIN)/python benchmarks/bench_fabric_kernel.py
	$(BIN)/python benchmarks/bench_shell.py

clean:
	rm -rf out .pytest_cache
