# tensor-servo: one Makefile for set-up, build, tests, demo and benchmarks.
#   make demo    the main job on the embedded default robot (PUMA 560)
#   make test    the whole suite (C++ unit tests, pytest: model, tools, RTL cocotb benches)
#   make setup   Debian packages (if missing), .venv with pinned versions, the C++ model and bindings
#   make bench   benchmark tables (docs/benchmarks.md)
#   make golden  regenerate tb/golden/ from the model
#   make synth   ECP5 / 7-series resources and post-route Fmax of the RTL (docs/resources.md)
#   make synth-core  the whole servo core placed and routed, default on LFE5U-85F, compact on LFE5U-45F
#                (over an hour: each routing is stopped after ROUTE_MINUTES, default 50)
#   make lint    verilator -Wall and iverilog on every RTL parameter set; HLS kernel checks
#   make soak    the Verilated core against the model, 10,000 ticks per chain and configuration
SHELL := /bin/bash
.DEFAULT_GOAL := help

VENV    := .venv
PY      := $(VENV)/bin/python
PIP     := $(VENV)/bin/pip
BUILD   := build
JOBS    ?= $(shell nproc 2>/dev/null || echo 2)
# Build the C++ objects in parallel too (every rule orders itself after the set-up stamps).
MAKEFLAGS += -j$(JOBS)

CXX      ?= g++
CXXSTD   := -std=c++17
CXXWARN  := -Wall -Wextra -Werror=return-type
CXXOPT   := -O2
INCLUDES := -Imodel/include -I/usr/include/eigen3
DEPFLAGS  = -MMD -MP

PKG      := model/python/tensor_servo
STAMP_APT  := $(BUILD)/.apt.stamp
STAMP_VENV := $(VENV)/.stamp

.PHONY: help setup build test test-cpp test-py demo soak bench golden lint lint-rtl synth synth-core clean distclean hls-csim hls-lint hls-tables regs regs-check regs-html

help:
	@sed -n '2,10p' Makefile | sed 's/^# //'

# ---- set-up ------------------------------------------------------------------------------------
$(STAMP_APT): scripts/setup_system.sh
	@mkdir -p $(BUILD)
	bash scripts/setup_system.sh
	@touch $@

$(STAMP_VENV): requirements.lock requirements-headers.txt pyproject.toml | $(STAMP_APT)
	test -x $(PY) || python3 -m venv $(VENV)
	$(PIP) install -q --disable-pip-version-check -r requirements.lock
	$(PIP) install -q --disable-pip-version-check --no-deps -r requirements-headers.txt
	$(PIP) install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
	@touch $@

# Paths that only the venv knows (evaluated lazily, after set-up).
PYEXT    = $(shell $(PY) -c "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))")
PYBIND   = $(shell $(PY) -m pybind11 --includes)
AP_TYPES = $(shell $(PY) -c "import importlib.util as u, os; print(os.path.join(u.find_spec('hls4ml').submodule_search_locations[0], 'templates/vivado/ap_types'))")

setup: $(STAMP_VENV) build

# ---- build ---------------------------------------------------------------------------------------
MODEL_HDRS := $(wildcard model/include/tensor_servo/*.hpp)
TEST_SRCS  := $(wildcard model/tests/*.cpp)
TEST_OBJS  := $(patsubst model/tests/%.cpp,$(BUILD)/model_tests/%.o,$(TEST_SRCS))
BIND_SRCS  := $(wildcard model/bindings/*.cpp)
BIND_OBJS  := $(patsubst model/bindings/%.cpp,$(BUILD)/bindings/%.o,$(BIND_SRCS))
BIND_STAMP := $(BUILD)/.bindings.stamp

build: $(BUILD)/model_tests/run_tests $(BUILD)/model_tests/operand_widths $(BIND_STAMP)

# Operand-width audit: its own program (TS_AUDIT_MUL changes the model's operator*).
$(BUILD)/model_tests/operand_widths: model/tests/audit/operand_widths.cpp $(MODEL_HDRS) | $(STAMP_VENV)
	@mkdir -p $(@D)
	$(CXX) $(CXXSTD) $(CXXOPT) $(CXXWARN) -DTS_AUDIT_MUL $(INCLUDES) $< -o $@

# Xilinx's ap_types headers warn under -Wall; they are third-party (-isystem) and quietened here.
AP_QUIET := -Wno-uninitialized -Wno-maybe-uninitialized

$(BUILD)/model_tests/%.o: model/tests/%.cpp | $(STAMP_VENV)
	@mkdir -p $(@D)
	$(CXX) $(CXXSTD) $(CXXOPT) $(CXXWARN) $(AP_QUIET) $(DEPFLAGS) $(INCLUDES) -isystem $(AP_TYPES) -c $< -o $@

$(BUILD)/model_tests/run_tests: $(TEST_OBJS)
	$(CXX) $(CXXOPT) $^ -o $@

$(BUILD)/bindings/%.o: model/bindings/%.cpp | $(STAMP_VENV)
	@mkdir -p $(@D)
	$(CXX) $(CXXSTD) $(CXXOPT) $(CXXWARN) $(DEPFLAGS) -fPIC -fvisibility=hidden $(INCLUDES) $(PYBIND) -c $< -o $@

# Linked to a temporary name and renamed, so a concurrent import never sees a missing module.
$(BIND_STAMP): $(BIND_OBJS)
	$(CXX) -shared $^ -o $(PKG)/.tmp_model$(PYEXT)
	mv -f $(PKG)/.tmp_model$(PYEXT) $(PKG)/_model$(PYEXT)
	@touch $@

-include $(wildcard $(BUILD)/model_tests/*.d $(BUILD)/bindings/*.d)

# ---- tests ---------------------------------------------------------------------------------------
test: setup
	$(BUILD)/model_tests/run_tests
	$(BUILD)/model_tests/operand_widths
	$(PY) -m pytest -n $(JOBS) -q --durations=30

test-cpp: build
	$(BUILD)/model_tests/run_tests
	$(BUILD)/model_tests/operand_widths

test-py: build
	$(PY) -m pytest -n $(JOBS) -q

# ---- the main job --------------------------------------------------------------------------------
demo: setup
	$(PY) -m tensor_servo.demo

# tb/test_rtl_track.py at length: every chain in closed loop through the Verilated core, 10,000
# ticks at 2 sweeps, both configurations, compared tick by tick with the model (~15 min on 2 cores).
SOAK_TICKS ?= 10000
soak: setup
	TS_RTL_TICKS=$(SOAK_TICKS) TS_RTL_SWEEPS=2 $(PY) -m pytest -n $(JOBS) -q -rA tb/test_rtl_track.py -k bit_identical

bench: setup
	$(PY) scripts/bench.py

golden: setup
	$(VENV)/bin/tservo golden -o tb/golden

lint: setup hls-lint lint-rtl

lint-rtl: setup
	PYTHON=$(PY) bash scripts/lint_rtl.sh -j $(JOBS)

# Yosys synth_ecp5 + nextpnr-ecp5 (LFE5U-85F -6, 3 seeds) and synth_xilinx counts; about an hour on 2
# cores (54 min for the run recorded in docs/resources.md, 2026-11-22).
synth: setup
	$(PY) scripts/synth.py --jobs $(JOBS)

# The whole core (both configurations side by side, router2, each on the smallest ECP5 its counts
# fit: default LFE5U-85F, compact LFE5U-45F; synth_ecp5 -nowidelut; router2's alternate weights,
# without which the default core does not route): counts of every engine, post-route Fmax, cycles
# per tick -> the generated core section of docs/resources.md. The same command as the recorded run
# there (tb/test_synth_core.py checks it; 1 h 7 min on 2 cores, 2026-12-07). A routing still running
# after ROUTE_MINUTES (the compact core's on LFE5U-45F does not converge at the current RTL) is
# stopped and reported with its last router2 iteration; ROUTE_MINUTES= (empty) lets it run.
ROUTE_MINUTES ?= 50
synth-core: setup
	$(PY) scripts/synth_core.py --no-widelut --router2-alt-weights $(if $(ROUTE_MINUTES),--route-minutes $(ROUTE_MINUTES))

# ---- register map (rtl/ts_servo_regs.rdl -> Verilog, C header, Python, docs) -------------------------
regs: setup
	$(PY) scripts/gen_regs.py

regs-check: setup
	$(PY) scripts/gen_regs.py --check

regs-html: setup
	$(PY) scripts/gen_regs.py --html $(BUILD)/regs-html

# ---- HLS (C-simulation with g++; Vitis users: hls/run_hls.tcl, docs/hls.md) -----------------------
hls-csim: build
	$(PY) hls/tb/csim.py

hls-lint: setup
	$(PY) scripts/hls_lint.py

hls-tables: setup
	$(PY) hls/gen_tables.py

clean:
	rm -rf $(BUILD) $(PKG)/_model.*.so
	find . -name __pycache__ -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)
