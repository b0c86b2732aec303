# outcrop — the only build entry.
#
#   make deps    install missing Debian packages (apt-get; root or sudo)
#   make         library (static + shared), Lua module, `outcrop` binary
#   make test    deps, build, every test, plus the ASan/UBSan pass
#   make demo    deps, build, run examples/demo.lua, say where outputs are
#   make pictures  build, run the examples that make the README's pictures,
#                copy those into docs/ (PICTURES below says which is which)
#   make bench   deps, build, run scripts/bench/ (prints `name: value unit`)
#   make compare-revisions OLD=rev [NEW=rev]  build an earlier commit and
#                the working tree (or NEW) side by side, compare every
#                output byte for byte and the benchmark figures
#                (scripts/compare_revisions.sh; ROUNDS=n, OUTPUTS=0 for timing only)
#   make fuzz    the scene fuzzer, long run (FUZZ_TIME seconds; fuzz-smoke:
#                FUZZ_SMOKE_TIME = 60 s after its build, part of make test)
#
# Objects go to build/release (or build/asan for the sanitizer pass, made
# by a recursive make with SAN=1).

SHELL := /bin/bash
PKGS := gcc g++ make pkg-config lua5.4 liblua5.4-dev libopenimageio-dev \
        openimageio-tools libopenexr-dev openexr lua-busted check libqhull-dev
# clang with libFuzzer and its OpenMP, for the fuzz build (fuzz-smoke runs
# in make test, so make deps installs them too)
FUZZ_PKGS := clang-14 libclang-rt-14-dev libomp-14-dev
PKGS += $(FUZZ_PKGS)

SAN ?= 0
ifeq ($(SAN),1)
  B ?= build/asan
  OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined \
         -fno-sanitize-recover=all
else
  B ?= build/release
  OPT := -O2 -g
endif

CC := gcc
CXX := g++

# The fuzz build (FUZZ=1, by make fuzz and fuzz-smoke): clang with
# libFuzzer's coverage instrumentation, ASan and UBSan, in build/fuzz.
ifeq ($(FUZZ),1)
  B := build/fuzz
  CC := clang-14
  CXX := clang++-14
  # (-Wno-pass-failed: at -O1 under the sanitizers clang cannot honour
  # the `omp simd` hints of the hot loops and says so for each one)
  OPT := -O1 -g -fno-omit-frame-pointer -Wno-pass-failed \
         -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
endif
PKGCONF = pkg-config
LUA_CFLAGS = $(shell $(PKGCONF) --cflags lua5.4 2>/dev/null)
LUA_LIBS = $(shell $(PKGCONF) --libs lua5.4 2>/dev/null)
OIIO_CFLAGS = $(shell $(PKGCONF) --cflags OpenImageIO 2>/dev/null)
OIIO_LIBS = $(shell $(PKGCONF) --libs OpenImageIO 2>/dev/null)
CHECK_LIBS = $(shell $(PKGCONF) --libs check 2>/dev/null)

# -ffp-contract=off: no fused multiply-add, so results do not depend on
# what the compiler chose to contract (determinism).
COMMON := $(OPT) -fPIC -fopenmp -ffp-contract=off -Wall -Wextra
# The engine, its tests and tools see every lib header (INC); the front
# ends see outcrop.h alone (below).
INC = -Ilib
CFLAGS = -std=c17 -D_POSIX_C_SOURCE=200809L $(COMMON) $(INC)
CXXFLAGS = -std=c++17 $(COMMON) $(INC)
LDLIBS := -lqhull_r -lm -fopenmp -ldl -lpthread

LIB_SRC := $(shell find lib -name '*.c' | sort)
# The OpenImageIO bridge (the only C++) is a shared object of its own,
# liboutcrop_oiio.so, that lib/io loads on the first image read or write
# (lib/io/oiio_load.c): programs that touch no image start without
# OpenImageIO's libraries. It carries private copies of two helpers that
# allocate nothing (lib/io/oiio_glue.h).
GLUE_SRC := $(wildcard lib/io/*.cpp)
GLUE_OBJ := $(GLUE_SRC:%.cpp=$(B)/%.o) $(B)/lib/core/error.o \
            $(B)/lib/io/infile.o
LUA_SRC := $(wildcard bindings/lua/*.c)
RT_SRC := $(wildcard runtime/*.c)
CTEST_SRC := $(wildcard tests/c/test_*.c)
CTEST_SUPPORT := $(filter-out $(CTEST_SRC),$(wildcard tests/c/*.c))

LIB_OBJ := $(LIB_SRC:%.c=$(B)/%.o)
LUA_OBJ := $(LUA_SRC:%.c=$(B)/%.o)
RT_OBJ := $(RT_SRC:%.c=$(B)/%.o)
CTEST_BIN := $(CTEST_SRC:tests/c/%.c=$(B)/tests/%)
CTEST_SUPPORT_OBJ := $(CTEST_SUPPORT:%.c=$(B)/%.o)

LIBA := $(B)/liboutcrop.a
LIBSO := $(B)/liboutcrop.so
MODULE := $(B)/outcrop.so
BIN := $(B)/outcrop
# (found next to the program or module holding lib/io, or one folder up:
# the tests, benchmarks and fuzzers are built in sub-folders of $(B))
GLUE := $(B)/liboutcrop_oiio.so

.PHONY: bench-peer-deps all deps test check-c check-lua check-lua-gc check-runtime check-asan demo bench \
        clean format tests-bin pictures compare-revisions
.DEFAULT_GOAL := all

all: $(LIBA) $(LIBSO) $(MODULE) $(BIN) $(GLUE)
	@ln -sf release/outcrop build/outcrop-bin 2>/dev/null || true

# The bindings and the interpreter are compiled against a folder holding
# a copy of the public header alone, so that including an internal lib
# header (core/..., io/...) fails the build: the front ends use the C API
# that C users have.
PUBINC := $(B)/include
$(LUA_OBJ) $(RT_OBJ): INC = -I$(PUBINC)
$(LUA_OBJ) $(RT_OBJ): | $(PUBINC)/outcrop.h
$(PUBINC)/outcrop.h: lib/outcrop.h
	@mkdir -p $(dir $@)
	cp $< $@

deps:
	@missing=""; for p in $(PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'install ok installed' \
	    || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "make deps: installing$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing; \
	else echo "make deps: all packages present"; fi

$(B)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -MMD -MP $(LUA_CFLAGS) -c $< -o $@

$(B)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -MMD -MP $(OIIO_CFLAGS) -c $< -o $@

$(LIBA): $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

# The bridge exports only its entry (lib/io/oiio_glue.map).
$(GLUE): $(GLUE_OBJ) lib/io/oiio_glue.map
	$(CXX) -shared -o $@ $(GLUE_OBJ) -Wl,--version-script=lib/io/oiio_glue.map \
	  $(OIIO_LIBS) $(LDLIBS) $(OPT)

# -z nodelete: lua_close dlcloses the module, which would unmap libgomp
# under its idle worker threads (a segfault at exit, one run in three
# under stock lua5.4); the objects stay loaded until the process ends.
NODELETE := -Wl,-z,nodelete

$(LIBSO): $(LIB_OBJ) | $(GLUE)
	$(CC) -shared -o $@ $^ $(LDLIBS) $(OPT) $(NODELETE)

# The module is loaded into stock lua5.4, which provides the Lua symbols.
$(MODULE): $(LUA_OBJ) $(LIB_OBJ) | $(GLUE)
	$(CC) -shared -o $@ $^ $(LDLIBS) $(OPT) $(NODELETE)

# The interpreter counts the allocations of the engine and the bindings
# for --max-memory (runtime/memory.c): --wrap sends their calls, and only
# theirs, to counting wrappers.
RT_WRAP := -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free \
           -Wl,--wrap=strdup,--wrap=realpath

$(BIN): $(RT_OBJ) $(LUA_OBJ) $(LIB_OBJ) | $(GLUE)
	$(CC) -o $@ $^ $(RT_WRAP) $(LUA_LIBS) $(LDLIBS) $(OPT)

$(B)/tests/%: tests/c/%.c $(CTEST_SUPPORT_OBJ) $(LIBA) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests/c -o $@ $< $(CTEST_SUPPORT_OBJ) $(LIBA) \
	  $(CHECK_LIBS) $(LDLIBS)

tests-bin: $(CTEST_BIN)

# ---- tests -------------------------------------------------------------

# Two test programs at a time (most run on one thread); each one's output
# is printed whole when it ends. Check's timeouts are tripled, as two
# programs share the cores (the sanitizer pass runs unforked: no timeouts).
CTEST_JOBS ?= 2
check-c: $(CTEST_BIN)
	@printf '%s\n' $(CTEST_BIN) | xargs -P$(CTEST_JOBS) -I{} sh -c \
	  '{ echo "== {}"; CK_TIMEOUT_MULTIPLIER=3 CK_VERBOSITY=minimal {}; } \
	   >{}.log 2>&1; s=$$?; cat {}.log; exit $$s' \
	  || { echo "check-c: a C test failed (above)"; exit 1; }

# OpenImageIO's dependency tree (its log4cplus) starts a thread when it
# is loaded; a test forked by Check after its parent had loaded it would
# hang in exit() waiting for that thread. The tests link no OpenImageIO:
# the bridge is loaded by the first image read or write, in the forked
# child that does it; CK_FORK=no in the sanitizer pass is a second guard.

LUA_SPEC_ENV = OUTCROP_TEST_BUILD=$(abspath $(B)) \
  LUA_CPATH="$(abspath $(B))/?.so;;" LUA_PATH="$(abspath tests/lua)/?.lua;;"

check-lua: $(MODULE) $(BIN)
	@echo "== busted specs ($(B))"
	@cd tests/lua && $(LUA_SPEC_ENV) $(SPEC_PRELOAD) lua5.4 /usr/bin/busted \
	  --lua=lua5.4 -o utfTerminal .

# The specs that exercise lifetimes and callbacks once more with the
# collector at its most aggressive (tests/lua/helpers/gcstress.lua), as
# luv's CI does: a use after free shows at once. Tests tagged #slowgc are
# left out of this pass (they run in the others): they build big meshes,
# images or 100 000-node chains, where a collection at every allocation
# costs minutes under the sanitizer and finds nothing their lifetime
# tests do not. heightfield_spec passes too but adds 4 minutes (its
# callbacks are in hostile_spec): GC_SPECS="..." to choose.
GC_SPECS := hostile_spec.lua gc_spec.lua mesh_spec.lua render_spec.lua \
  render_elevation_spec.lua

check-lua-gc: $(MODULE)
	@echo "== busted specs, eager collector ($(B))"
	@cd tests/lua && OUTCROP_GC_STRESS=1 $(LUA_SPEC_ENV) $(SPEC_PRELOAD) \
	  lua5.4 /usr/bin/busted --lua=lua5.4 -o utfTerminal \
	  --exclude-tags=slowgc $(GC_SPECS)

check-runtime: $(BIN)
	@echo "== interpreter tests ($(B))"
	@OUTCROP=$(abspath $(BIN)) bash tests/runtime/run.sh
	@OUTCROP=$(abspath $(BIN)) bash tests/runtime/outpaths.sh
	@OUTCROP=$(abspath $(BIN)) bash tests/runtime/examples.sh
	@[ "$(SNIPPETS)" = 0 ] || OUTCROP=$(abspath $(BIN)) bash tests/runtime/readme_snippets.sh

# The sanitizer pass: C tests, Lua specs (stock lua5.4 with libasan
# preloaded; leak checking off there because lua5.4 itself is not
# instrumented) and the interpreter tests with leak checking on (the
# README snippets, which call what the specs call, only in the release
# pass: the 20-minute budget).
ASAN_PRELOAD = ASAN_OPTIONS=detect_leaks=0 \
  LD_PRELOAD=$$(gcc -print-file-name=libasan.so):$$(gcc -print-file-name=libubsan.so)
check-asan:
	@$(call STAGE,SAN=1 all tests-bin)
	@export CK_FORK=no; $(call STAGE,SAN=1 check-c)
	@$(call STAGE,SAN=1 check-lua SPEC_PRELOAD="$(ASAN_PRELOAD)",SAN=1 check-lua)
	@$(call STAGE,SAN=1 check-lua-gc SPEC_PRELOAD="$(ASAN_PRELOAD)",SAN=1 check-lua-gc)
	@export EXAMPLES_THREADS=2; $(call STAGE,SAN=1 SNIPPETS=0 check-runtime)
	@$(call STAGE,SAN=1 check-corpus)
	@$(call STAGE,SAN=1 check-alloc)

# Tests share the two cores (two C programs at a time, each on up to two
# threads): idle OpenMP threads sleep instead of spinning at barriers,
# which burnt up to 9x the CPU of a one-thread run when oversubscribed.
# Benchmarks keep the default policy.
test check-c check-lua check-lua-gc check-runtime check-asan check-corpus \
  check-alloc fuzz-smoke: export OMP_WAIT_POLICY = passive

# Each stage says how long it took (the whole must stay under 20 minutes
# on 2 cores; see README, Tests).
STAGE = t0=$$(date +%s); $(MAKE) --no-print-directory $(1) && \
  echo "make test: $(or $(2),$(1)) took $$(( $$(date +%s) - t0 )) s"

test: deps
	@$(call STAGE,all tests-bin)
	@$(call STAGE,check-c)
	@$(call STAGE,check-lua)
	@$(call STAGE,check-runtime)
	@$(call STAGE,check-asan)
	@$(call STAGE,fuzz-smoke)
	@echo "make test: all tests passed"

demo: deps
	@$(MAKE) --no-print-directory all
	@mkdir -p out/demo
	$(BIN) run examples/demo.lua --out out/demo
	@echo "demo outputs are in $(abspath out/demo)/"

# The README's pictures, each `docs/PICTURE:EXAMPLE:OUTPUT`: `make
# pictures` runs every example named once (into out/pictures/EXAMPLE) and
# copies its outputs over the pictures, so that they cannot go stale.
PICTURES := demo_arch_render.png:demo:arch_render.png \
  demo_arch_xz.png:demo:arch_xz.png \
  example_canyon.png:canyon:canyon.png \
  example_floating_islands.png:floating_islands:floating_islands.png \
  example_hf_render.png:hf_render:hf_render.png \
  example_hoodoos.png:hoodoos:hoodoos.png \
  example_karst.png:karst:karst_network.png \
  example_karst_cut.png:karst:karst.png \
  example_sea_cliffs.png:sea_cliffs:sea_cliffs.png \
  example_elev_river.png:elev_river:elev_river.png \
  example_elev_dunes.png:elev_dunes:elev_dunes.png \
  example_elev_instances.png:elev_instances:elev_instances.png \
  example_elev_road.png:elev_road:elev_road.png \
  example_elev_coast.png:elev_coast:elev_coast.png \
  example_elev_lake.png:elev_lake:elev_lake.png \
  example_elev_craters.png:elev_craters:elev_craters.png \
  example_elev_multiscale.png:elev_multiscale:elev_multiscale.png \
  example_elev_lod.png:elev_lod:elev_lod.png \
  example_diffusion_ridges.png:diffusion_ridges:diffusion_ridges.png \
  example_diffusion_river_cliff.png:diffusion_river_cliff:diffusion_river_cliff.png \
  example_diffusion_hill_crack.png:diffusion_hill_crack:diffusion_hill_crack.png \
  example_diffusion_noise.png:diffusion_noise:diffusion_noise.png \
  example_diffusion_island.png:diffusion_island:diffusion_island.png \
  example_diffusion_canyon_15.png:diffusion_canyon:diffusion_canyon_15.png \
  example_diffusion_canyon_30.png:diffusion_canyon:diffusion_canyon_30.png \
  example_diffusion_canyon_74.png:diffusion_canyon:diffusion_canyon_74.png \
  example_diffusion_canyon3d.png:diffusion_canyon3d:diffusion_canyon3d.png \
  example_layers_sand.png:layers_sand:layers_sand.png \
  example_layers_ravine.png:layers_ravine:layers_ravine.png \
  example_layers_arches.png:layers_arches:layers_arches.png \
  example_layers_caves.png:layers_caves:layers_caves.png \
  example_layers_canyon.png:layers_canyon:layers_canyon.png \
  example_blocks_types.png:blocks_types:blocks_types.png \
  example_blocks_authored.png:blocks_authored:blocks_authored.png \
  example_blocks_canyon.png:blocks_canyon:blocks_canyon.png \
  example_blocks_sea_cliff.png:blocks_sea_cliff:blocks_sea_cliff.png \
  example_blocks_sea_spire.png:blocks_sea_spire:blocks_sea_spire.png \
  example_blocks_inset.png:blocks_inset:blocks_inset.png \
  example_blocks_warp.png:blocks_warp:blocks_warp.png
PICTURE_SCENES := $(sort $(foreach p,$(PICTURES),$(word 2,$(subst :, ,$(p)))))

pictures: all
	@set -e; for e in $(PICTURE_SCENES); do \
	  echo "== examples/$$e.lua"; rm -rf out/pictures/$$e; \
	  $(BIN) run examples/$$e.lua --out out/pictures/$$e; \
	done; \
	for p in $(PICTURES); do \
	  IFS=: read -r pic scene file <<<"$$p"; \
	  cp out/pictures/$$scene/$$file docs/$$pic; echo "docs/$$pic <- examples/$$scene.lua ($$file)"; \
	done

BENCH_SRC := $(wildcard scripts/bench/bench_*.c)
BENCH_BIN := $(BENCH_SRC:scripts/bench/%.c=$(B)/bench/%)

$(B)/bench/%: scripts/bench/%.c $(LIBA) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -o $@ $< $(LIBA) $(LDLIBS)

# The peer comparison (OpenVDB's volumeToMesh) is optional: it is built only
# when libopenvdb-dev is installed (`make bench-peer-deps` installs it).
# (libopenvdb-dev needs Boost's headers but does not depend on them.)
VDB_PKGS := libopenvdb-dev libboost-dev
HAVE_VDB := $(shell for p in $(VDB_PKGS); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'install ok installed' || exit 1; done && echo 1)
PEER_SRC := $(if $(HAVE_VDB),$(wildcard scripts/bench/peer_*.cpp))
PEER_BIN := $(PEER_SRC:scripts/bench/%.cpp=$(B)/bench/%)

$(B)/bench/peer_%: scripts/bench/peer_%.cpp $(LIBA) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -o $@ $< $(LIBA) -lopenvdb -ltbb $(LDLIBS)

bench-peer-deps:
	@$(MAKE) --no-print-directory deps PKGS="$(VDB_PKGS)"

bench: deps
	@$(MAKE) --no-print-directory all $(BENCH_BIN) $(PEER_BIN)
	@OUTCROP=$(abspath $(BIN)) BENCH_BIN="$(abspath $(BENCH_BIN) $(PEER_BIN))" \
	  bash scripts/bench/run.sh

# Outputs (examples, golden scenes, benchmark meshes) and benchmark
# figures of OLD against the working tree or NEW, in one run.
compare-revisions:
	@test -n "$(OLD)" || { echo "usage: make compare-revisions OLD=rev [NEW=rev]" >&2; exit 2; }
	@bash scripts/compare_revisions.sh $(OLD) $(NEW)

# ---- fuzzing (tests/fuzz, tests/corpus) ------------------------------
.PHONY: fuzz fuzz-smoke fuzz-pending fuzz-deps fuzz-bin check-corpus \
        check-alloc
# One generator turns bytes into a Lua scene (tests/fuzz/gen.c); the
# libFuzzer target (clang, FUZZ=1) and the corpus replayer (any build)
# share it with the runner (a sandboxed state with a heap cap and an
# instruction budget). scripts/fuzz-show FILE prints the scene of a file.
# Inputs starting with the bytes FE 02 are read by the grammar's version 2
# (elevation trees, diffusion, blocks, layers); every other input by
# version 1, which never changes, so stored cases keep their scenes.

FUZZ_SUPPORT := tests/fuzz/gen.c tests/fuzz/runner.c
# (of the interpreter only the sandbox and the stop: memory.c's wrappers
# need the interpreter's --wrap link)
FUZZ_SUPPORT_OBJ := $(FUZZ_SUPPORT:%.c=$(B)/%.o) \
  $(B)/runtime/sandbox.o $(B)/runtime/stop.o $(LUA_OBJ) $(LIB_OBJ)
FUZZ_LINK = $(LUA_LIBS) $(LDLIBS) $(OPT)

$(B)/fuzz/fuzz_scene: $(B)/tests/fuzz/fuzz_scene.o $(FUZZ_SUPPORT_OBJ) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ -fsanitize=fuzzer $(FUZZ_LINK)

$(B)/fuzz/replay: $(B)/tests/fuzz/replay.o $(FUZZ_SUPPORT_OBJ) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(FUZZ_LINK)

fuzz-deps:
	@$(MAKE) --no-print-directory deps PKGS="$(FUZZ_PKGS)"

fuzz-bin:
	@$(MAKE) --no-print-directory FUZZ=1 build/fuzz/fuzz/fuzz_scene

# libFuzzer options: inputs up to 512 bytes (about 40 statements), 10 s
# per input at most, 2 GiB of RSS. The long run keeps what adds coverage
# in build/fuzz/corpus (seeded from tests/corpus) and its findings in
# build/fuzz/crashes: each one is to be kept as a file of tests/corpus
# (or tests/corpus/pending). $(1): seconds, $(2): environment, $(3):
# corpus folder, $(4): more options.
FUZZ_TIME ?= 3600
# the smoke run of make test, seconds
FUZZ_SMOKE_TIME ?= 60
FUZZ_OPTS = -max_len=512 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
FUZZ_LONG_OPTS = -fork=1 -ignore_crashes=1 -ignore_timeouts=1
FUZZ_SMOKE_SKIP ?=
# (libFuzzer reads corpus folders recursively: the seeds are copied, so
# that tests/corpus/pending stays out.)
fuzz-run = @mkdir -p $(3) build/fuzz/crashes && \
  find tests/corpus -maxdepth 1 -type f -exec cp {} $(3)/ \; && \
  OMP_NUM_THREADS=1 $(2) ASAN_OPTIONS=detect_leaks=1 \
  build/fuzz/fuzz/fuzz_scene $(FUZZ_OPTS) -max_total_time=$(1) \
  -artifact_prefix=build/fuzz/crashes/ $(4) $(3)

fuzz: fuzz-deps fuzz-bin
	$(call fuzz-run,$(FUZZ_TIME),,build/fuzz/corpus,$(FUZZ_LONG_OPTS))

# A short run from tests/corpus alone, the whole grammar; a part whose
# findings are still open (tests/corpus/pending) can be left out with
# FUZZ_SMOKE_SKIP=close,huge (see tests/fuzz/gen.h). It stops at the
# first finding.
fuzz-smoke: fuzz-bin
	@rm -rf build/fuzz/smoke
	$(call fuzz-run,$(FUZZ_SMOKE_TIME),OCFUZZ_SKIP=$(FUZZ_SMOKE_SKIP),build/fuzz/smoke,)

# The findings left to other branches (tests/corpus/pending), through the
# fuzz build: each one still failing prints its report and is listed.
fuzz-pending: fuzz-bin
	@fail=""; for f in tests/corpus/pending/*; do [ -e "$$f" ] || continue; \
	  OMP_NUM_THREADS=1 build/fuzz/fuzz/fuzz_scene -timeout=20 $$f \
	    >build/fuzz/pending.log 2>&1 || { fail="$$fail $$f"; \
	    grep -m3 -E 'ERROR|runtime error|SUMMARY' build/fuzz/pending.log; }; \
	done; echo "fuzz-pending: still failing:$${fail:- none}"

# Every corpus file (not tests/corpus/pending) under the current build.
check-corpus: $(B)/fuzz/replay
	@echo "== corpus replay ($(B))"
	@OMP_NUM_THREADS=2 $(B)/fuzz/replay tests/corpus

# Allocation-failure injection (tests/alloc): the engine's malloc family
# is wrapped at link time so that the Nth call can fail.
ALLOC_WRAP := -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free

$(B)/alloc/alloc: $(B)/tests/alloc/alloc.o $(FUZZ_SUPPORT_OBJ) | $(GLUE)
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(ALLOC_WRAP) $(FUZZ_LINK)

check-alloc: $(B)/alloc/alloc
	@echo "== allocation-failure injection ($(B))"
	@OMP_NUM_THREADS=1 $(B)/alloc/alloc

format:
	clang-format -i $$(find lib bindings runtime tests/c scripts -name '*.[ch]' -o -name '*.cpp' -o -name '*.hpp')

clean:
	rm -rf build out

-include $(shell find build -name '*.d' 2>/dev/null)
