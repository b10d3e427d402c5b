# SPDX-License-Identifier: GPL-3.0-or-later
# Conveyor simulator: one Makefile for the core library, the CLI, the daemon,
# the tests and the benchmarks. `make` builds, `make run` starts the daemon,
# `make test` runs every test, `make check` runs them under ASan+UBSan,
# `make deps` installs what is missing, `make install` installs,
# `make bench` writes the work-precision tables, `make bench-dem` the feed
# against LIGGGHTS (docs/dem.md), `make fuzz` runs the
# libFuzzer harnesses, `make load` runs a bounded load test. V=1 shows the commands.

CC      ?= cc
CFLAGS  ?= -O2 -g
WARN    := -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
LDLIBS  := -lm -lpthread
GSL_LIBS := -lgsl -lgslcblas
BUILD   ?= build
PORT    ?= 8080
HOST    ?= 127.0.0.1
PREFIX  ?= /usr/local
DESTDIR ?=
BINDIR  ?= $(PREFIX)/bin
DATADIR ?= $(PREFIX)/share/convsim
DOCDIR  ?= $(PREFIX)/share/doc/convsim
UNITDIR ?= $(PREFIX)/lib/systemd/system

ifeq ($(V),1)
Q :=
else
Q := @
endif

# Open MPI installed (pkg-config ompi-c) and not NO_MPI=1: convsim-mpi is
# built, the command line with MPI (and LIGGGHTS where installed): it
# spreads a study's points over the ranks under mpirun (cli/spread.h:
# spread_mpi.c) and runs feed_model=liggghts. The plain convsim links
# neither (spread_none.c, coupled_none.c) and hands those two over to it
# (cli/handover.h). `make NO_MPI=1 BUILD=DIR` builds without MPI (and
# so without the DEM coupling, which needs it) where it is installed;
# `make test` builds that too, in $(BUILD)/nompi.
HAVE_MPI := $(if $(NO_MPI),,$(shell pkg-config --exists ompi-c 2>/dev/null && echo yes))
# LIGGGHTS (and MPI) installed: the DEM coupling (dem/, below) is built
HAVE_LIGGGHTS := $(if $(HAVE_MPI),$(wildcard /usr/include/liggghts/library.h))
CORE_SRC   := $(wildcard core/*.c)
CLI_SRC    := $(filter-out cli/spread_mpi.c,$(wildcard cli/*.c))
FIT_SRC    := $(wildcard fit/*.c)
API_SRC    := $(wildcard api/*.c)
# server/ in floors (docs/development.md "Architecture"), bottom to top
SERVER_FLOORS := base store admit jobs session http
SERVER_SRC := $(foreach f,$(SERVER_FLOORS),$(wildcard server/$(f)/*.c)) server/main.c
UNIT_SRC   := $(wildcard tests/unit/test_*.c)

CORE_OBJ   := $(CORE_SRC:%.c=$(BUILD)/%.o)
CLI_OBJ    := $(CLI_SRC:%.c=$(BUILD)/%.o)
FIT_OBJ    := $(FIT_SRC:%.c=$(BUILD)/%.o)
API_OBJ    := $(API_SRC:%.c=$(BUILD)/%.o)
SERVER_OBJ := $(SERVER_SRC:%.c=$(BUILD)/%.o)
UNIT_BIN   := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)

# The DEM coupling (dem/: LIGGGHTS and MPI, which core/ never sees) is
# built only where LIGGGHTS is installed; `make test` and `make bench-dem`
# install it first (DEB_DEM) and then build it in a second make, which
# sees the new header.
DEM_SRC     := $(wildcard dem/*.c)
DEM_CLI_SRC := dem/cli/convsim_dem.c
DEM_OBJ     := $(DEM_SRC:%.c=$(BUILD)/%.o)
DEM_CLI_OBJ := $(DEM_CLI_SRC:%.c=$(BUILD)/%.o)
DEM_BIN     := $(if $(HAVE_LIGGGHTS),$(BUILD)/convsim-dem $(BUILD)/convsim-bed)
# The daemon's side of a LIGGGHTS session (docs/dem.md "The bed process"):
# the coupling and the client of the bed process, built everywhere and
# without LIGGGHTS or MPI (convsimd never links them); the bed process,
# convsim-bed, is built where LIGGGHTS is installed.
DEM_LINK_SRC := dem/couple.c dem/feed_remote.c dem/bed_proto.c dem/bed_spec.c
DEM_LINK_OBJ := $(DEM_LINK_SRC:%.c=$(BUILD)/demlink/%.o)
# convsim-mpi: the CLI's objects with spread_mpi.c for spread_none.c and,
# where LIGGGHTS is installed, the coupled runner and its libraries for
# coupled_none.c; what it has is compiled into handover.c (CLI_MPI_BUILD)
CLI_DEM_OBJ := $(if $(HAVE_LIGGGHTS),$(BUILD)/dem/cli/run_coupled.o $(BUILD)/libdem.a)
CLI_DEM_LIBS = $(if $(HAVE_LIGGGHTS),-lliggghts)
CLI_MPI_OBJ := $(filter-out $(BUILD)/cli/spread_none.o $(if $(HAVE_LIGGGHTS),$(BUILD)/cli/coupled_none.o),\
                $(CLI_OBJ)) $(BUILD)/cli/spread_mpi.o $(CLI_DEM_OBJ)
CLI_MPI_BIN := $(if $(HAVE_MPI),$(BUILD)/convsim-mpi)
CLI_MPI_HAS := $(if $(HAVE_MPI),$(if $(HAVE_LIGGGHTS),3,1),0)
MPI_CFLAGS  := $(if $(HAVE_MPI),$(shell pkg-config --cflags ompi-c))
MPI_LIBS    := $(if $(HAVE_MPI),$(shell pkg-config --libs ompi-c))

# Debian packages the project needs, by the file each provides: to build
# and run (`make`, `make run`), and in addition to test (`make test`,
# `make install`'s unit check).
DEB_BUILD := /usr/include/microhttpd.h:libmicrohttpd-dev \
             /usr/include/cjson/cJSON.h:libcjson-dev \
             /usr/include/gsl/gsl_multifit_nlinear.h:libgsl-dev
# and to build the unit tests (`make` builds them)
DEB_UNIT  := /usr/include/cmocka.h:libcmocka-dev
DEB_TEST  := $(DEB_UNIT) \
             /usr/bin/curl:curl \
             /usr/bin/python3:python3 \
             /usr/bin/node:nodejs \
             /usr/bin/npm:npm \
             /usr/bin/chromium:chromium \
             /usr/bin/systemd-analyze:systemd \
             /usr/sbin/haproxy:haproxy \
             /usr/bin/clang:clang \
             /usr/bin/valgrind:valgrind
# and in addition to benchmark (`make bench`: the ODE peers).
DEB_BENCH := /usr/include/cvode/cvode.h:libsundials-dev \
             /usr/include/gsl/gsl_odeiv2.h:libgsl-dev
# and in addition to profile the daemon (`make profile-daemon`).
DEB_PROFILE := /usr/bin/perf:linux-perf
# and in addition for the DEM coupling (dem/, `make test`, `make bench-dem`):
# LIGGGHTS's C library, whose header includes <mpi.h>, and mpirun.
DEB_DEM   := /usr/lib/x86_64-linux-gnu/libliggghts.so:libliggghts-dev \
             /usr/bin/liggghts:liggghts \
             /usr/lib/x86_64-linux-gnu/pkgconfig/ompi-c.pc:libopenmpi-dev \
             /usr/bin/mpirun:openmpi-bin \
             /usr/bin/pkg-config:pkg-config

.PHONY: profile-daemon bench-advance-cost fast-feed-check model-check bench-dem-calibrate all deps deps-build deps-unit run cluster test check check-ci bench bench-controls bench-control-loop bench-control-cost bench-control-shaping bench-calibration bench-dem bench-dem-map bench-dem-inputs dem-build bench-peers bench-zoo-ref load flood mutate fuzz fuzz-build clean install uninstall
# `make` builds the unit tests too, so it installs cmocka (deps-unit) as well
# as what building and running need.
all: deps-build deps-unit $(BUILD)/convsim $(CLI_MPI_BIN) $(BUILD)/convsimd $(UNIT_BIN) $(DEM_BIN)

# Install what is missing: Debian packages (with apt-get, which needs root:
# run as root or have sudo) and the npm test tools (tests/node_modules, no
# root). Says what it installs and why; idempotent. deps-build is the part
# that building and running need.
deps: deps-build $(BUILD)/.deps $(BUILD)/.deps-dem
deps-build: $(BUILD)/.deps-build
deps-unit: $(BUILD)/.deps-unit
$(BUILD)/.deps-build: Makefile
	$(Q)NEEDS="$(DEB_BUILD)" WHY="to build and run convsim" sh tests/apt-deps.sh
	$(Q)mkdir -p $(BUILD) && touch $@
$(BUILD)/.deps-unit: Makefile
	$(Q)NEEDS="$(DEB_UNIT)" WHY="to build the unit tests that make builds" sh tests/apt-deps.sh
	$(Q)mkdir -p $(BUILD) && touch $@
$(BUILD)/.deps: Makefile tests/package.json tests/package-lock.json
	$(Q)NEEDS="$(DEB_TEST)" WHY="to run the tests (cmocka, node, chromium, systemd-analyze, haproxy, clang for libFuzzer, valgrind)" sh tests/apt-deps.sh
	$(Q)if [ ! -d tests/node_modules/playwright-core ] || [ ! -d tests/node_modules/ajv ] || \
	   [ ! -d tests/node_modules/@apidevtools/swagger-parser ] || [ ! -d tests/node_modules/@stoplight/prism-cli ]; then \
	  echo "npm ci in tests/ (the test tools of tests/package.json, into tests/node_modules; no root)"; \
	  (cd tests && npm ci --no-audit --no-fund --loglevel=error) || exit 1; fi
	$(Q)mkdir -p $(BUILD) && touch $@
$(BUILD)/.deps-dem: Makefile
	$(Q)NEEDS="$(DEB_DEM)" WHY="to cross-check and couple the feed with the LIGGGHTS DEM code (dem/)" sh tests/apt-deps.sh
	$(Q)mkdir -p $(BUILD) && touch $@
$(BUILD)/.deps-bench: Makefile
	$(Q)NEEDS="$(DEB_BENCH)" WHY="to benchmark against the ODE peers (GSL, SUNDIALS)" sh tests/apt-deps.sh
	$(Q)mkdir -p $(BUILD) && touch $@

# Include floors, by the directory of the source (docs/development.md
# "Architecture"): a floor's -I flags name its own directory and the floors
# below it, so a header included upward fails the build. core/ sees only
# core/; fit/ (the calibration library) core/ and GSL; api/ core/ and fit/;
# the application cli/ (convsim) core/ and fit/; server/'s floors, bottom
# to top, base/ < store/ < admit/ < jobs/ < session/ < http/ <
# server/main.c, each core/,
# fit/, api/ and the floors below it (session/ and up also dem/'s headers:
# the LIGGGHTS-free client of the bed process, libdemlink.a); dem/ core/
# and LIGGGHTS, its programs dem/cli/ also cli/ (convsim's coupled run);
# the unit tests core/, fit/ and api/ (the libraries they link).
INC_core   := -Icore
INC_fit    := -Icore -Ifit
INC_api    := -Icore -Ifit -Iapi
INC_cli    := -Icore -Ifit -Icli
INC_server_base    := $(INC_api) -Iserver/base
INC_server_store   := $(INC_server_base) -Iserver/store
INC_server_admit   := $(INC_server_store) -Iserver/admit
INC_server_jobs    := $(INC_server_admit) -Iserver/jobs
INC_server_session := $(INC_server_jobs) -Iserver/session -Idem
INC_server_http    := $(INC_server_session) -Iserver/http
INC_server := $(INC_server_http)
INC_tests  := $(INC_api)
INC_dem    := -Icore -Idem -I/usr/include/liggghts $(MPI_CFLAGS)
INC_dem_cli := $(INC_dem) -Icli
$(BUILD)/cli/spread_mpi.o: INC_EXTRA := $(MPI_CFLAGS)
$(BUILD)/cli/handover.o: INC_EXTRA := -DCLI_MPI_BUILD=$(CLI_MPI_HAS)
# CLI_MPI_HAS follows what is installed when make starts: `make run` builds
# convsim before `make test` installs MPI and LIGGGHTS. The value is kept in
# a file rewritten only when it changes, and handover.o depends on it, so
# the hand-over is compiled again when the packages arrive.
HANDOVER_MPI := $(BUILD)/cli/handover.mpi
$(shell mkdir -p $(BUILD)/cli && { [ "$$(cat $(HANDOVER_MPI) 2>/dev/null)" = "$(CLI_MPI_HAS)" ] || echo $(CLI_MPI_HAS) > $(HANDOVER_MPI); })
$(BUILD)/cli/handover.o: $(HANDOVER_MPI)

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CFLAGS) $(WARN) -MMD -MP $(INC_$(subst /,_,$(patsubst %/,%,$(dir $*)))) $(INC_EXTRA) -c $< -o $@

# The OpenAPI document's response and stream schemas, api/schemas.json,
# become one C string literal (api/openapi.c includes it).
$(BUILD)/api/schemas.inc: api/schemas.json
	@mkdir -p $(dir $@)
	$(Q)sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/^/"/' -e 's/$$/\\n"/' $< > $@
$(BUILD)/api/openapi.o: $(BUILD)/api/schemas.inc
$(BUILD)/api/openapi.o: INC_EXTRA := -I$(BUILD)/api

# The DEM map's points with the column model's v (tests/bench/model_check.py
# writes the CSV) become rows of a C table that core/model_check.c includes:
# the core reads no file at run time. Columns are found by their header.
MODEL_MAP := tests/bench/results/model_check.csv
$(BUILD)/core/model_map.inc: $(MODEL_MAP) Makefile
	@mkdir -p $(dir $@)
	$(Q)awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$$i] = i; next } \
	  /^[^#]/ { printf "{\"%s\", \"%s\", \"%s\", \"%s\", %d, %s, %s, %s, %s, %d, %s},\n", \
	    $$c["preset"], $$c["settings"], $$c["material"], $$c["model"], $$c["layers"], $$c["beta_deg"], \
	    $$c["rotation"] == "cw" ? "SIM_CW" : "SIM_CCW", $$c["v_dem"], \
	    $$c["v_dem_sd"] == "nan" ? "NAN" : $$c["v_dem_sd"], $$c["seeds"], $$c["v_column"] }' \
	  $< > $@
# `make model-check` computes the table again from the DEM data (after new
# rows in tests/bench/results/dem_map.csv or a change of the column model).
model-check: $(BUILD)/convsim
	$(Q)python3 tests/bench/model_check.py $(BUILD)/convsim > $(MODEL_MAP).new && mv $(MODEL_MAP).new $(MODEL_MAP)
	$(Q)python3 tests/bench/dem_map_plot.py > tests/bench/results/dem_map.svg
	$(Q)python3 tests/bench/model_error_check.py
# `make bench-dem-calibrate` calibrates the column model on three points of
# each complete bed of the DEM map (mu the material's, k_c and R fitted),
# predicts the rest and checks how far a point's seed spread moves the result
# (tests/bench/dem_calibrate.py: tests/bench/results/dem_calibration.md,
# tests/bench/model_presets.csv), then computes the table above again. About
# 15 minutes of 2 cores; not part of `make bench` (it changes the table the
# build compiles in).
bench-dem-calibrate: $(BUILD)/convsim
	$(Q)python3 tests/bench/dem_calibrate.py $(BUILD)/convsim > /dev/null
	$(Q)$(MAKE) --no-print-directory model-check
$(BUILD)/core/model_check.o: $(BUILD)/core/model_map.inc
# `make fast-feed-check`: reduced feed models against the DEM map, leave one
# depth out (tests/bench/fast_feed_check.py, docs/feed-models.md), into
# tests/bench/results/fast_feed.md and .csv; the docs' tables follow.
fast-feed-check: $(BUILD)/convsim $(BUILD)/fast_feed_bed
	$(Q)python3 tests/bench/fast_feed_check.py $(BUILD)/convsim
	$(Q)python3 tests/bench/depth_surrogate.py
	$(Q)python3 tests/docs_bench.py
$(BUILD)/core/model_check.o: INC_EXTRA := -I$(BUILD)/core
# the `grains` candidate's bed (tests/bench/fast_feed_bed.c), standalone
$(BUILD)/fast_feed_bed: tests/bench/fast_feed_bed.c
	@mkdir -p $(@D)
	$(Q)$(CC) $(CFLAGS) $(WARN) -o $@ $< -lm

$(BUILD)/libcore.a: $(CORE_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/libfit.a: $(FIT_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/libapi.a: $(API_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

# dem/'s LIGGGHTS-free part for the daemon, compiled without LIGGGHTS's or
# MPI's include paths: a LIGGGHTS header included there fails the build
$(BUILD)/demlink/%.o: %.c
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $< (daemon)")
	$(Q)$(CC) $(CFLAGS) $(WARN) -MMD -MP -Icore -Idem -c $< -o $@

$(BUILD)/libdemlink.a: $(DEM_LINK_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/libdem.a: $(DEM_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/convsim-dem: $(DEM_CLI_OBJ) $(BUILD)/cli/options.o $(BUILD)/libdem.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lliggghts $(MPI_LIBS) $(GSL_LIBS) $(LDLIBS)

$(BUILD)/convsim-bed: $(BUILD)/dem/cli/convsim_bed.o $(BUILD)/libdem.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lliggghts $(MPI_LIBS) $(LDLIBS)

dem-build: $(BUILD)/convsim-dem $(BUILD)/convsim-bed $(BUILD)/convsim $(CLI_MPI_BIN)

# the plain convsim: neither MPI nor LIGGGHTS (tests/cli/mpi.test.mjs reads
# its ldd), and GSL from its archive where that is installed: two shared
# libraries fewer to map at every start (about 1 ms of a short run's 7,
# tests/bench/startup.sh)
GSL_STATIC_LIBS := -Wl,-Bstatic $(GSL_LIBS) -Wl,-Bdynamic
CLI_GSL_LIBS := $(if $(filter /%,$(shell $(CC) -print-file-name=libgsl.a)),$(GSL_STATIC_LIBS),$(GSL_LIBS))
$(BUILD)/convsim: $(CLI_OBJ) $(BUILD)/libfit.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ $(CLI_GSL_LIBS) $(LDLIBS)

$(BUILD)/convsim-mpi: $(CLI_MPI_OBJ) $(BUILD)/libfit.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ $(GSL_LIBS) $(CLI_DEM_LIBS) $(MPI_LIBS) $(LDLIBS)

$(BUILD)/convsimd: $(SERVER_OBJ) $(BUILD)/libapi.a $(BUILD)/libdemlink.a $(BUILD)/libfit.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lmicrohttpd -lcjson $(GSL_LIBS) $(LDLIBS)

$(BUILD)/tests/%: tests/unit/%.c $(BUILD)/libapi.a $(BUILD)/libfit.a $(BUILD)/libcore.a | $(BUILD)/.deps-unit
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CFLAGS) $(WARN) -MMD -MP $(INC_tests) -o $@ $^ -lcmocka -lcjson $(GSL_LIBS) $(LDLIBS)

# Builds only the daemon it runs. PORT, HOST and DAEMON_FLAGS (any of
# `build/convsimd --help`) are the knobs; the daemon's state (sessions,
# checkpoints, results) lives in DATA and survives a restart. The daemon
# always runs with a token: TOKEN (a file) is made once, mode 0600, from
# 32 bytes of /dev/urandom, and the dashboard's address is printed with
# the token in its fragment (#token=..., never sent to a server).
DATA    ?= var/data
TOKEN   ?= var/token
run: deps-build $(BUILD)/convsimd
	$(Q)mkdir -p $(DATA) $(dir $(TOKEN))
	$(Q)[ -s $(TOKEN) ] || (umask 077 && head -c 32 /dev/urandom | od -An -tx1 | \
	  tr -d ' \n' > $(TOKEN) && echo "made a token in $(TOKEN) (mode 0600)")
	$(Q)$(BUILD)/convsimd --listen $(HOST) --port $(PORT) --data-dir $(DATA) \
	  --token-file $(TOKEN) $(DAEMON_FLAGS) | while IFS= read -r line; do \
	  echo "$$line"; case $$line in "listening on "*) url=$${line#listening on }; \
	  url=$$(echo "$$url" | sed -e 's,//0\.0\.0\.0:,//127.0.0.1:,' -e 's,//\[::\]:,//[::1]:,'); \
	  echo "dashboard: $$url/#token=$$(cat $(TOKEN))"; \
	  echo "curl:      curl -H \"Authorization: Bearer \$$(cat $(TOKEN))\" $$url/api/v1/sessions";; \
	  esac; done

# N replicas (--node-id n1..nN, --data-dir var/cluster/nK) behind one HAProxy
# on PROXY_PORT (18700): server/cluster.sh, whose header lists the knobs
# (PROXY_PORT, PORTS, DIR, DAEMON_FLAGS, TOKEN_FILE, SERVER_NAME, HEARTBEAT,
# given here or in the environment). Ctrl-C stops everything.
N       ?= 3
cluster: deps-build $(BUILD)/convsimd
	$(Q)N=$(N) CONVSIMD=$(BUILD)/convsimd bash server/cluster.sh run

# make test, make check and make fuzz build on JOBS cores (every core by
# default; JOBS=1 one file at a time), once what is missing is installed;
# tests/run.sh runs the unit tests JOBS at a time, the rest one by one
JOBS ?= $(shell nproc 2>/dev/null || echo 1)
test: deps deps-unit
	$(Q)$(MAKE) --no-print-directory -j$(JOBS) all
	$(Q)$(MAKE) --no-print-directory -j$(JOBS) dem-build
	$(Q)$(MAKE) --no-print-directory -j$(JOBS) NO_MPI=1 BUILD=$(BUILD)/nompi $(BUILD)/nompi/convsim
	$(Q)BUILD=$(BUILD) TESTS_SKIP='$(TESTS_SKIP)' TEST_JOBS=$(JOBS) TEST_LANES=$(or $(TEST_LANES),1) bash tests/run.sh

check:
	$(Q)$(MAKE) --no-print-directory BUILD=build-san \
	  CFLAGS="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" test

# CI's sanitizer pass (.ci/run, after make test and make fuzz): every group
# but those whose C paths the rest already drive and that cost two thirds of
# the sanitizer time: the examples and the OpenAPI tour behind the
# validating proxy (the same routes as tests/http/), the browser tests (the
# daemon's routes again), LIGGGHTS and MPI (uninstrumented libraries), the
# CLI's long fits (fit/ under tests/unit/), the licences (skipped there),
# and test_fit_band: 20 fits and a 200-sample band, 300 CPU s under the
# sanitizers (fit/'s paths run instrumented in test_fit, fits.test.mjs and
# sweep_band.test.mjs; its coverage claims in the release pass), and
# restore_exact.test.mjs: bit-exactness after kills, 110 s instrumented in
# daemon restarts and waits (the same checkpoint and restore paths run
# instrumented in persistence, durability, upgrade, test_checkpoint and
# the checkpoint fuzzer). Its node:test files run two at a time
# (TEST_LANES): under a sanitizer build timeouts scale and the asserts that
# need a quiet machine are relaxed (SLOW), and the pass's wall time is
# mostly theirs waiting on the daemon
CHECK_CI_SKIP = ^test_fit_band\b|^tests/(web|dem)/|^tests/http/(openapi|docs|cluster|restore_exact)\.test|^tests/cli/(mpi|fit|licences)\.test
check-ci:
	$(Q)$(MAKE) --no-print-directory TESTS_SKIP='$(CHECK_CI_SKIP)' TEST_LANES=2 check

bench: all $(BUILD)/.deps-bench
	$(Q)BUILD=$(BUILD) bash tests/bench/run.sh

# The paper's case of docs/calibration.md alone (tests/bench/calibration.sh,
# also part of `make bench`): seven peak fits of the czubak2016 model, a few
# minutes of two cores; writes tests/bench/results/calibration.md.
bench-calibration: all
	$(Q)BUILD=$(BUILD) bash tests/bench/calibration.sh > /dev/null

# The machine zoo's converged references (tests/bench/zoo/ref.tsv, which
# `make bench`'s zoo.sh reads): one to two hours of CPU. ZOO="stiff deep"
# redoes those machines only.
bench-zoo-ref: all
	$(Q)BUILD=$(BUILD) bash tests/bench/zoo_ref.sh tests/bench/zoo/ref.tsv $(ZOO)

# libFuzzer harnesses (tests/fuzz/, docs/fuzzing.md "Fuzzing"): clang builds core/,
# fit/, api/ and server/ into build-fuzz/ with coverage and ASan+UBSan, each
# harness runs FUZZ_SECONDS on its committed corpus (new inputs go to
# build-fuzz/corpus/, crashes to build-fuzz/crashes/) and a table of
# executions, coverage and crashes is printed. A JSON body is one more
# word in FUZZ_BODIES (and one row of tests/fuzz/fuzz_body.c's table).
# (-Wno-unused-function: clang, unlike gcc, warns of an unused static
# inline function in a .c file.)
FUZZ_SECONDS ?= 60
FUZZ_BUILD   := build-fuzz
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_BODIES  := session control controlline experiment sweep fit specfile
FUZZ_NAMES   := $(FUZZ_BODIES:%=body_%) query route checkpoint store jobs peers
FUZZ_BINS    := $(FUZZ_NAMES:%=$(BUILD)/fuzz/%)
FUZZ_SERVER  := $(filter-out $(BUILD)/server/main.o,$(SERVER_OBJ))
FUZZ_LIBS    := $(FUZZ_SERVER) $(BUILD)/libapi.a $(BUILD)/libdemlink.a $(BUILD)/libfit.a $(BUILD)/libcore.a

fuzz: deps-build
	$(Q)$(MAKE) --no-print-directory -j$(JOBS) BUILD=$(FUZZ_BUILD) CC=clang \
	  CFLAGS="-O1 -g $(FUZZ_SAN) -fsanitize=fuzzer-no-link" WARN="$(WARN) -Wno-unused-function" fuzz-build
	$(Q)FUZZ_BUILD=$(FUZZ_BUILD) FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_RUNS=$(FUZZ_RUNS) FUZZ_NAMES="$(FUZZ_NAMES)" \
	  FUZZ_JOBS=$(JOBS) bash tests/fuzz/run.sh

fuzz-build: $(FUZZ_BINS)

$(BUILD)/fuzz/body_%: tests/fuzz/fuzz_body.c tests/fuzz/fuzz_util.c $(FUZZ_LIBS)
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  FUZZ    $@")
	$(Q)$(CC) $(CFLAGS) $(WARN) -fsanitize=fuzzer -DFUZZ_BODY='"$*"' $(INC_server) -o $@ \
	  $(filter %.c,$^) $(FUZZ_LIBS) -lmicrohttpd -lcjson $(GSL_LIBS) $(LDLIBS)

$(BUILD)/fuzz/%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_util.c $(FUZZ_LIBS)
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  FUZZ    $@")
	$(Q)$(CC) $(CFLAGS) $(WARN) -fsanitize=fuzzer $(INC_server) -o $@ \
	  $(filter %.c,$^) $(FUZZ_LIBS) -lmicrohttpd -lcjson $(GSL_LIBS) $(LDLIBS)

# PATCH throughput with the durable control log alone (part of `make
# bench`; tests/bench/controls.mjs, about 20 s): OLD_CONVSIMD=path adds
# another build's rows for comparison; CLIENT=fetch,lean both clients.
bench-controls: all
	$(Q)CONVSIMD=$(BUILD)/convsimd OLD="$(OLD_CONVSIMD)" CLIENT="$(or $(CLIENT),lean)" node tests/bench/controls.mjs

# The conveyor as a control system (part of `make bench`;
# tests/bench/control_loop.mjs, about 10 s): identification, setpoint steps
# and disturbances on the preset, into tests/bench/results/control_loop.md.
bench-control-loop: all
	$(Q)CONVSIMD=$(BUILD)/convsimd node tests/bench/control_loop.mjs | tee tests/bench/results/control_loop.md

# What the closed loop itself costs against an earlier build
# (tests/bench/control_cost.mjs, about 30 s; not part of `make bench`: the
# comparison needs OLD_CONVSIMD=path, a convsimd built from an earlier
# commit): a control experiment against a schedule of the same betas, on
# a data directory, into tests/bench/results/control_cost.md.
bench-control-cost: all
	$(Q)test -n "$(OLD_CONVSIMD)" || { echo "bench-control-cost: give OLD_CONVSIMD=path, an earlier build's convsimd"; exit 2; }
	$(Q). tests/bench/provenance.sh && line=$$(provenance) && \
	  CONVSIMD=$(BUILD)/convsimd OLD="$(OLD_CONVSIMD)" node tests/bench/control_cost.mjs > tests/bench/results/control_cost.md && \
	  stamp tests/bench/results/control_cost.md "$$line Command: \`make bench-control-cost OLD_CONVSIMD=$(OLD_CONVSIMD)\`." && \
	  cat tests/bench/results/control_cost.md

# The simulation of a default session in the daemon's pattern (sample by
# sample, hundreds of instances in turn) against one long run, in one
# process (tests/bench/advance_cost.sh, about a minute; callgrind where
# valgrind is installed). Into tests/bench/results/advance_cost.md.
$(BUILD)/advance_cost: tests/bench/advance_cost.c $(BUILD)/libcore.a
	$(Q)$(CC) $(CFLAGS) $(WARN) $(INC_core) -o $@ $< $(BUILD)/libcore.a $(LDLIBS)
bench-advance-cost: $(BUILD)/advance_cost
	$(Q)bash tests/bench/advance_cost.sh

# Does shaping the beta command settle the feed faster (part of `make bench`;
# tests/bench/control_shaping.c on the core alone, about 10 s)? Into
# tests/bench/results/control_shaping.md.
bench-control-shaping: all
	$(Q)$(CC) $(CFLAGS) $(WARN) $(INC_core) -o $(BUILD)/control_shaping tests/bench/control_shaping.c \
		$(BUILD)/libcore.a $(LDLIBS)
	$(Q)$(BUILD)/control_shaping | tee tests/bench/results/control_shaping.md

# A bounded load run on loopback (about two minutes; tests/bench/load.mjs):
# 200 sessions, 500 streams, PATCH beta, 2,000 idle sockets from one client;
# prints a table and fails if the daemon crashed, went over its memory
# budget or stopped answering another client.
load: all
	$(Q)CONVSIMD=$(CURDIR)/$(BUILD)/convsimd node tests/bench/load.mjs

# Connection floods on loopback (about a minute; tests/bench/flood.mjs):
# 2,000 idle, slow-GET and slow-POST sockets from 500 addresses, an active
# client's p50 / p99 meanwhile; fails if it or /api/v1/health went
# unanswered. With BASELINE=another convsimd (each flood on both in turn;
# ROUNDS, LOAD: see the script) the table also goes to
# tests/bench/results/flood.md, whose figures docs/hardening.md quotes.
flood: all
	$(Q)if [ -n "$$BASELINE" ]; then \
	  CONVSIMD=$(CURDIR)/$(BUILD)/convsimd node tests/bench/flood.mjs > tests/bench/results/flood.md.new; \
	  st=$$?; cat tests/bench/results/flood.md.new; mv tests/bench/results/flood.md.new tests/bench/results/flood.md; exit $$st; \
	else CONVSIMD=$(CURDIR)/$(BUILD)/convsimd node tests/bench/flood.mjs; fi

# The feed against LIGGGHTS (tests/bench/dem.sh, docs/dem.md): one DEM
# process at a time, niced, into tests/bench/results/dem.md; then the
# coupled scene's cost against grains and ranks (tests/bench/dem_cost.sh,
# dem_cost.md).
bench-dem: all $(BUILD)/.deps-dem
	$(Q)$(MAKE) --no-print-directory dem-build
	$(Q)BUILD=$(BUILD) bash tests/bench/dem.sh
	$(Q)BUILD=$(BUILD) bash tests/bench/dem_cost.sh

# The DEM reference map (tests/bench/dem_map.sh, docs/dem.md "The map"):
# named materials, depths 1-16 grains, beta every 15 deg, two drives, three
# seeds a point, from one build; many CPU hours, resumable, in parts
# (DEM_MAP_PARTS="glass-shallow glass-checks"; DEM_MAP_JOBS=3 runs a
# point's three seeds at once), into
# tests/bench/results/dem_map.csv and dem_map.md.
bench-dem-map: $(BUILD)/.deps-build $(BUILD)/.deps-dem
	$(Q)bash tests/bench/dem_map.sh
# How far the map moves with the contact values it assumes (glass on the
# deck and its rolling; wheat's restitution, friction between grains and
# rolling), one at a time at seven points, by the map's build
# (tests/bench/dem_inputs.py, about an hour of a core): dem_inputs.csv, .md.
bench-dem-inputs: $(BUILD)/.deps-build $(BUILD)/.deps-dem
	$(Q)bash tests/bench/dem_map.sh inputs

# Where a daemon of paced default sessions spends its CPU, beside the
# previous build (tests/bench/profile.sh, docs/performance.md; about a
# minute): both built with frame pointers into build-prof/, PROFILE_N
# sessions (200) with a stream each, `perf record -g` for PROFILE_SECONDS
# (8), into tests/bench/results/profile.md. perf is linux-perf.
PROFILE_N       ?= 200
PROFILE_SECONDS ?= 8
profile-daemon: $(BUILD)/.deps-build $(BUILD)/.deps-profile
	$(Q)PROFILE_N=$(PROFILE_N) PROFILE_SECONDS=$(PROFILE_SECONDS) bash tests/bench/profile.sh
$(BUILD)/.deps-profile: Makefile
	$(Q)NEEDS="$(DEB_PROFILE)" WHY="to profile the daemon (perf)" sh tests/apt-deps.sh
	$(Q)mkdir -p $(BUILD) && touch $@

# The GSL and SUNDIALS peers at the 1 % gate alone (part of `make bench`;
# tests/bench/peers.sh), into tests/bench/results.
bench-peers: all $(BUILD)/.deps-bench
	$(Q)BUILD=$(BUILD) bash tests/bench/peers.sh tests/bench/results "make bench-peers"

# Deliberate faults, each of which `make test` must notice (tests/mutate.sh).
mutate: all
	$(Q)bash tests/mutate.sh

# The binaries, the dashboard, the docs and a hardened systemd unit under
# $(DESTDIR)$(PREFIX); the unit is checked with systemd-analyze verify when
# that exists and DESTDIR is empty (the unit names the installed paths).
install: deps-build $(BUILD)/convsim $(CLI_MPI_BIN) $(BUILD)/convsimd
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(DATADIR) $(DESTDIR)$(DOCDIR) $(DESTDIR)$(UNITDIR)
	install -m 755 $(BUILD)/convsim $(CLI_MPI_BIN) $(BUILD)/convsimd $(DESTDIR)$(BINDIR)/
	rm -rf $(DESTDIR)$(DATADIR)/web && cp -R web $(DESTDIR)$(DATADIR)/web
	chmod -R u=rwX,go=rX $(DESTDIR)$(DATADIR)/web
	install -m 644 README.md LICENSE $(DESTDIR)$(DOCDIR)/
	install -d $(DESTDIR)$(DOCDIR)/docs $(DESTDIR)$(DOCDIR)/docs/img $(DESTDIR)$(DOCDIR)/docs/log $(DESTDIR)$(DOCDIR)/docs/examples
	install -m 644 docs/*.md $(DESTDIR)$(DOCDIR)/docs/
	install -m 644 docs/log/*.md $(DESTDIR)$(DOCDIR)/docs/log/
	install -m 644 docs/img/*.png $(DESTDIR)$(DOCDIR)/docs/img/
	install -m 644 docs/examples/*.py $(DESTDIR)$(DOCDIR)/docs/examples/
	sed -e 's|@BINDIR@|$(BINDIR)|g' -e 's|@WEBDIR@|$(DATADIR)/web|g' -e 's|@DOCDIR@|$(DOCDIR)|g' \
	  server/convsimd.service.in > $(DESTDIR)$(UNITDIR)/convsimd.service
	chmod 644 $(DESTDIR)$(UNITDIR)/convsimd.service
	$(Q)if [ -z "$(DESTDIR)" ] && command -v systemd-analyze >/dev/null 2>&1; then \
	  echo "systemd-analyze verify $(UNITDIR)/convsimd.service"; \
	  systemd-analyze verify $(UNITDIR)/convsimd.service || exit 1; \
	else echo "(systemd-analyze not run: DESTDIR set or systemd-analyze missing)"; fi

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/convsim $(DESTDIR)$(BINDIR)/convsim-mpi $(DESTDIR)$(BINDIR)/convsimd \
	  $(DESTDIR)$(UNITDIR)/convsimd.service
	rm -rf $(DESTDIR)$(DATADIR) $(DESTDIR)$(DOCDIR)

clean:
	rm -rf build build-san build-fuzz

-include $(DEM_OBJ:.o=.d) $(DEM_CLI_OBJ:.o=.d) $(BUILD)/dem/cli/run_coupled.d $(BUILD)/dem/cli/convsim_bed.d \
	$(BUILD)/cli/spread_mpi.d \
	$(DEM_LINK_OBJ:.o=.d)
-include $(CORE_OBJ:.o=.d) $(API_OBJ:.o=.d) $(SERVER_OBJ:.o=.d) $(CLI_OBJ:.o=.d) $(FIT_OBJ:.o=.d)
