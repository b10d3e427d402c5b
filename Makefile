# Conveyor simulator: one Makefile for the core library, the CLI, the daemon,
# the tests and the benchmarks. `make` builds, `make run` starts the daemon,
# `make test` runs every test, `make check` runs them under ASan+UBSan,
# `make bench` writes the work-precision tables. V=1 shows the commands.

CC      ?= cc
CFLAGS  ?= -O2 -g
WARN    := -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
LDLIBS  := -lm -lpthread
BUILD   ?= build
PORT    ?= 8080
HOST    ?= 127.0.0.1

ifeq ($(V),1)
Q :=
else
Q := @
endif

CORE_SRC   := $(wildcard core/*.c)
API_SRC    := $(wildcard api/*.c)
SERVER_SRC := $(wildcard server/*.c)
UNIT_SRC   := $(wildcard tests/unit/test_*.c)

CORE_OBJ   := $(CORE_SRC:%.c=$(BUILD)/%.o)
API_OBJ    := $(API_SRC:%.c=$(BUILD)/%.o)
SERVER_OBJ := $(SERVER_SRC:%.c=$(BUILD)/%.o)
UNIT_BIN   := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)

# Debian packages the project needs, by the file each provides.
DEB_NEEDS := /usr/include/microhttpd.h:libmicrohttpd-dev \
             /usr/include/cjson/cJSON.h:libcjson-dev \
             /usr/include/cmocka.h:libcmocka-dev \
             /usr/bin/curl:curl \
             /usr/bin/python3:python3 \
             /usr/bin/node:nodejs \
             /usr/bin/npm:npm \
             /usr/bin/chromium:chromium

.PHONY: all deps run test check bench mutate clean
all: deps $(BUILD)/convsim $(BUILD)/convsimd $(UNIT_BIN)

# Install what is missing (Debian packages, npm test tools). Idempotent.
deps: $(BUILD)/.deps
$(BUILD)/.deps: Makefile tests/package.json
	$(Q)missing=""; for pair in $(DEB_NEEDS); do f=$${pair%%:*}; p=$${pair##*:}; \
	  [ -e "$$f" ] || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then echo "apt-get install$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; fi
	$(Q)if [ ! -d tests/node_modules/playwright-core ]; then echo "npm ci (tests)"; \
	  (cd tests && npm ci --no-audit --no-fund --loglevel=error) || exit 1; fi
	$(Q)mkdir -p $(BUILD) && touch $@

# Include floors, by the top directory of the source: core/ (and its CLI)
# sees only core/, api/ sees core/ and api/, server/ all three; the unit
# tests see core/. A header included across a floor fails the build.
INC_core   := -Icore
INC_api    := -Icore -Iapi
INC_server := -Icore -Iapi -Iserver
INC_tests  := -Icore

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CFLAGS) $(WARN) -MMD -MP $(INC_$(firstword $(subst /, ,$*))) -c $< -o $@

$(BUILD)/libcore.a: $(CORE_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/libapi.a: $(API_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/convsim: $(BUILD)/core/cli/convsim.o $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/convsimd: $(SERVER_OBJ) $(BUILD)/libapi.a $(BUILD)/libcore.a
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lmicrohttpd -lcjson $(LDLIBS)

$(BUILD)/tests/%: tests/unit/%.c $(BUILD)/libapi.a $(BUILD)/libcore.a
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CFLAGS) $(WARN) -MMD -MP $(INC_tests) -o $@ $^ -lcmocka -lcjson $(LDLIBS)

# the daemon's state (sessions, checkpoints, results) survives a restart
DATA    ?= var/data
run: all
	$(Q)mkdir -p $(DATA)
	$(BUILD)/convsimd --listen $(HOST) --port $(PORT) --data-dir $(DATA)

test: all
	$(Q)BUILD=$(BUILD) bash tests/run.sh

check:
	$(Q)$(MAKE) --no-print-directory BUILD=build-san \
	  CFLAGS="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" test

bench: all
	$(Q)BUILD=$(BUILD) bash tests/bench/run.sh

# Deliberate faults, each of which `make test` must notice (tests/mutate.sh).
mutate: all
	$(Q)bash tests/mutate.sh

clean:
	rm -rf build build-san

-include $(CORE_OBJ:.o=.d) $(API_OBJ:.o=.d) $(SERVER_OBJ:.o=.d) $(BUILD)/core/cli/convsim.d
