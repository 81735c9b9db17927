# mica — build, run, test.
#
#   make deps       install whichever Debian package of DEB_PKGS is missing (apt-get, as root or with sudo)
#   make run        install missing Debian packages, build, run input/quickstart.cfg (a size-effect sweep)
#   make test       install, build, run the unit and verification tests
#   make test SAN=1 the same under AddressSanitizer + UndefinedBehaviorSanitizer
#   make docs       rewrite docs/input.md's settings tables from the schemas (mica help --markdown)
#   make bench      benchmarks (rates and ratios; never pass/fail on time)
#   make bench-peers mica against legacy FEniCS on the same problems (~15 min; docs/performance.md)
#   make fuzz       libFuzzer harnesses (tests/fuzz/) with ASan+UBSan, each run FUZZ_SECONDS (default 1800)
#
# Normal builds go to bin/ lib/ build/; sanitizer builds to build-san/ so both can coexist.
# `sudo bash tests/fresh_machine.sh` checks that make run and make test work on a fresh minimal Debian 12.

DEB_PKGS := libsuitesparse-dev liblapacke-dev libopenblas-dev libopenmpi-dev openmpi-bin libmetis-dev \
            libconfig-dev libcmocka-dev gnuplot-nox libmatheval-dev libgmsh-dev python3 petsc-dev pkg-config

# The C compiler: mpicc and the tests' reference programs run gcc, which libopenmpi-dev does not pull in
# (only gcc-12, without the gcc command).
DEB_PKGS += gcc libc6-dev

CC := mpicc
CSTD := -std=c11 -D_POSIX_C_SOURCE=200809L
WARN := -Wall -Wextra
OPT ?= -O2 -g
# PETSc (src/solve/linear_petsc.c) from pkg-config; its headers as system headers, so -Wall -Wextra judge mica's
# code only. Recursive (=): asked when a recipe runs, after `make deps` has installed petsc-dev in the same make
# (make run on a fresh machine); pkg-config runs once per compile, a few milliseconds.
PETSC_CFLAGS = $(patsubst -I%,-isystem %,$(shell pkg-config --cflags PETSc))
PETSC_LIBS = $(shell pkg-config --libs PETSc)
CPPFLAGS = -Iinclude -I/usr/include/suitesparse $(PETSC_CFLAGS)
LDLIBS = $(PETSC_LIBS) -lmetis -lconfig -lmatheval -lcholmod -lumfpack -lsuitesparseconfig -llapacke -llapack -lblas -lm

ifeq ($(SAN),1)
  OUT := build-san
  OPT := -O1 -g -fno-omit-frame-pointer
  SANFLAGS := -fsanitize=address,undefined -fno-sanitize-recover=undefined
  BIN := $(OUT)/bin
  LIB := $(OUT)/lib
else
  OUT := build
  SANFLAGS :=
  BIN := bin
  LIB := lib
endif

CFLAGS := $(CSTD) $(WARN) $(OPT) $(SANFLAGS) -MMD -MP
LDFLAGS := $(SANFLAGS)
OBJ := $(OUT)/obj

# The library is every folder of src/ but the application layer (the commands) and the program, which go into
# the mica binary and not into lib/libmica.a: a new library folder needs no edit here, only its place in the
# stage order of tests/cli/layering.sh (which refuses a folder it does not know).
PROGRAM_DIRS := app cli
LIB_DIRS := $(filter-out $(PROGRAM_DIRS),$(patsubst src/%/,%,$(wildcard src/*/)))
LIB_SRC := $(foreach d,$(LIB_DIRS),$(wildcard src/$(d)/*.c))
APP_SRC := $(wildcard src/app/*.c)
CLI_SRC := $(wildcard src/cli/*.c)
LIB_OBJ := $(LIB_SRC:%.c=$(OBJ)/%.o)
APP_OBJ := $(APP_SRC:%.c=$(OBJ)/%.o)
CLI_OBJ := $(CLI_SRC:%.c=$(OBJ)/%.o)
TEST_SRC := $(wildcard tests/unit/test_*.c)
TEST_BIN := $(TEST_SRC:tests/unit/%.c=$(OUT)/tests/%)
# Test-only types (tests/extensions/*.c, one file each, registering themselves): linked into a second CLI,
# $(OUT)/tests/mica-ext, and into the _ext variants of the unit tests that loop over a registry, which are told
# how many types the extensions add (EXT_COUNTS).
# Output types (tests/extensions/output_*.c) belong to the application layer's registry: mica-ext only.
EXT_SRC := $(wildcard tests/extensions/*.c)
EXT_APP_SRC := $(wildcard tests/extensions/output_*.c)
EXT_OBJ := $(EXT_SRC:%.c=$(OBJ)/%.o)
EXT_LIB_OBJ := $(filter-out $(EXT_APP_SRC:%.c=$(OBJ)/%.o),$(EXT_OBJ))
EXT_COUNTS := -DEXTRA_WEIGHTS=1 -DEXTRA_MODELS=1
EXT_TESTS := test_mls_weight test_models
EXT_BIN := $(OUT)/tests/mica-ext $(EXT_TESTS:%=$(OUT)/tests/%_ext)
BENCH_SRC := $(wildcard bench/bench_*.c)
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(OUT)/bench/%)

.PHONY: all deps run test docs bench bench-peers clean help
.DEFAULT_GOAL := all

all: $(BIN)/mica | deps

help:
	@sed -n '3,12p' Makefile

# Installs whichever Debian package of the list $(1) is missing (as root; sudo otherwise), naming the target
# $(2) in its messages. Cheap when nothing is.
define install_missing
	@missing=$$(for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "make $(2): installing" $$missing; \
	  sudo=""; [ "$$(id -u)" = 0 ] || sudo=sudo; \
	  $$sudo apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq --no-install-recommends $$missing \
	    || { echo "make $(2): apt-get failed; install these packages: $$missing" >&2; exit 1; }; \
	fi
endef

deps:
	$(call install_missing,$(DEB_PKGS),deps)

$(OBJ)/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

# lib/libmica.a holds one relocatable object per folder (build/obj/lib/FOLDER.o, `ld -r` of its objects) whose
# only global symbols are the public API, mica_* and mls_* (the MLS library's own prefix): a folder's cross-file
# functions (deck_*, gmsh_*, bc_point, redistribution_*, ...) become local to it, so nothing outside can call them
# (tests/cli/library_symbols.sh). Under SAN=1 the sanitizers' own globals stay global.
LIB_PARTS := $(LIB_DIRS:%=$(OBJ)/lib/%.o)
KEEP_GLOBAL := --keep-global-symbol='mica_*' --keep-global-symbol='mls_*'
ifeq ($(SAN),1)
  KEEP_GLOBAL += --keep-global-symbol='__asan*' --keep-global-symbol='__odr_asan*'
endif
$(foreach d,$(LIB_DIRS),$(eval $(OBJ)/lib/$(d).o: $(filter $(OBJ)/src/$(d)/%,$(LIB_OBJ))))
$(LIB_PARTS): $(OBJ)/lib/%.o:
	@mkdir -p $(dir $@)
	ld -r -o $@.tmp $^
	objcopy --wildcard $(KEEP_GLOBAL) $@.tmp $@ && rm -f $@.tmp

$(LIB)/libmica.a: $(LIB_PARTS)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(BIN)/mica: $(CLI_OBJ) $(APP_OBJ) $(LIB)/libmica.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $(CLI_OBJ) $(APP_OBJ) $(LIB)/libmica.a $(LDLIBS) -o $@

$(OUT)/tests/mica-ext: $(CLI_OBJ) $(APP_OBJ) $(EXT_OBJ) $(LIB)/libmica.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) $(CLI_OBJ) $(APP_OBJ) $(EXT_OBJ) $(LIB)/libmica.a $(LDLIBS) -o $@

$(OUT)/tests/%_ext: tests/unit/%.c $(EXT_LIB_OBJ) $(LIB)/libmica.a | deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(EXT_COUNTS) -Itests/unit $< $(EXT_LIB_OBJ) $(LIB)/libmica.a $(LDFLAGS) -lcmocka $(LDLIBS) -o $@

$(OUT)/tests/%: tests/unit/%.c $(LIB)/libmica.a | deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -Itests/unit $< $(LIB)/libmica.a $(LDFLAGS) -lcmocka $(LDLIBS) -o $@

$(OUT)/bench/%: bench/%.c $(LIB)/libmica.a | deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) $< $(LIB)/libmica.a $(LDFLAGS) $(LDLIBS) -o $@

run: all
	$(BIN)/mica sweep input/quickstart.cfg -o out/quickstart
	@echo "--- out/quickstart/summary.json"; cat out/quickstart/summary.json
	@echo "--- chart: out/quickstart/sweep.png; table: out/quickstart/sweep.csv"

test: $(BIN)/mica $(TEST_BIN) $(EXT_BIN) | deps
	@MICA_BIN=$(BIN)/mica MICA_EXT_BIN=$(OUT)/tests/mica-ext TEST_DIR=$(OUT)/tests OUT_DIR=$(OUT)/test-out SAN=$(SAN) bash tests/run.sh

# The generated blocks of docs/input.md (between <!-- generated: mica help --markdown ... --> and <!-- end generated -->),
# made by the binary from the schemas and registries; tests/cli/docs.sh fails when they differ from what it makes.
docs: $(BIN)/mica
	MICA_BIN=$(BIN)/mica bash docs/gen_input_tables.sh docs/input.md

bench: $(BIN)/mica $(BENCH_BIN) | deps
	@for b in $(BENCH_BIN); do echo "== $$b"; $$b || exit 1; done
	@for b in bench/bench_*.sh; do echo "== $$b"; MICA_BIN=$(BIN)/mica bash $$b || exit 1; done

# Not part of test or bench. Installs Debian's python3-dolfin (legacy FEniCS, for /usr/bin/python3) when missing.
bench-peers: $(BIN)/mica | deps
	@/usr/bin/python3 -c 'import dolfin' 2>/dev/null || { \
	  echo "make bench-peers: installing python3-dolfin"; \
	  sudo=""; [ "$$(id -u)" = 0 ] || sudo=sudo; \
	  $$sudo apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq --no-install-recommends python3-dolfin \
	    || { echo "make bench-peers: apt-get failed; install python3-dolfin" >&2; exit 1; }; }
	MICA_BIN=$(BIN)/mica /usr/bin/python3 bench/peers/peers.py

# ---- fuzzing (tests/fuzz/, docs/verification.md "Fuzzing"): clang's libFuzzer, only for `make fuzz` ----
# The library is built again with clang (through Open MPI's wrapper, OMPI_CC) into build-fuzz/, with coverage
# instrumentation and ASan+UBSan. Each harness runs FUZZ_SECONDS on one core, both at once, in libFuzzer's fork
# mode so that it goes on after a crash; new inputs and crash/timeout/OOM artifacts stay in build-fuzz/.
FUZZ_PKGS := clang libclang-rt-14-dev
FUZZ_CC ?= clang
FUZZ_SECONDS ?= 1800
FUZZ_TIMEOUT ?= 10
FUZZ_RSS_MB ?= 2048
FUZZ_OUT := build-fuzz
FUZZ_HARNESSES := $(patsubst tests/fuzz/fuzz_%.c,%,$(wildcard tests/fuzz/fuzz_*.c))
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_CFLAGS := $(CSTD) $(WARN) -O1 -g -fno-omit-frame-pointer $(FUZZ_SAN) -MMD -MP
# the library and the application layer (src/cli/commands.o names the commands of src/app)
FUZZ_LIB_OBJ := $(LIB_SRC:%.c=$(FUZZ_OUT)/obj/%.o) $(APP_SRC:%.c=$(FUZZ_OUT)/obj/%.o)
FUZZ_CLI_OBJ := $(FUZZ_OUT)/obj/src/cli/commands.o # the registry of commands and their schemas (not main)
.SECONDARY: $(FUZZ_CLI_OBJ)

.PHONY: fuzz fuzz-build fuzz-deps

fuzz-deps:
	$(call install_missing,$(FUZZ_PKGS),fuzz-deps)

$(FUZZ_OUT)/obj/%.o: %.c | deps fuzz-deps
	@mkdir -p $(dir $@)
	OMPI_CC=$(FUZZ_CC) mpicc $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -c $< -o $@

$(FUZZ_OUT)/libmica.a: $(FUZZ_LIB_OBJ)
	rm -f $@ && ar rcs $@ $^

$(FUZZ_OUT)/fuzz_%: tests/fuzz/fuzz_%.c $(FUZZ_CLI_OBJ) $(FUZZ_OUT)/libmica.a | deps fuzz-deps
	OMPI_CC=$(FUZZ_CC) mpicc $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_CLI_OBJ) $(FUZZ_OUT)/libmica.a \
	  $(LDLIBS) -o $@

fuzz-build: $(FUZZ_HARNESSES:%=$(FUZZ_OUT)/fuzz_%)

fuzz: fuzz-build
	@FUZZ_CC=$(FUZZ_CC) FUZZ_OUT=$(FUZZ_OUT) FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_TIMEOUT=$(FUZZ_TIMEOUT) FUZZ_RSS_MB=$(FUZZ_RSS_MB) \
	  bash tests/fuzz/run.sh $(FUZZ_HARNESSES)

clean:
	rm -rf build build-san build-fuzz bin lib out

-include $(LIB_OBJ:.o=.d) $(APP_OBJ:.o=.d) $(CLI_OBJ:.o=.d) $(EXT_OBJ:.o=.d) $(FUZZ_LIB_OBJ:.o=.d) $(FUZZ_CLI_OBJ:.o=.d)
