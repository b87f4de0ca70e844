# lamprig — the only entry point. See README.md.
#
#   make deps    install missing Debian packages (idempotent, silent when all present)
#   make         build build/bin/lamprig and the tools (build/bin/lamprig-*)
#   make test    build with -Werror + ASan + UBSan and run every test binary
#   make run     render the default candle scene headless
#   make bench   speed and error figures
#   make soak    the rig's soak at full length (test_fw_loop with LAMPRIG_SOAK_S=120; make
#                test runs it for 30 s)
#   make install  PREFIX=/usr/local DESTDIR= (see tools/install/README.md)
#   make deb      build/lamprig_VERSION_ARCH.deb from a staged install (tools/debian/)
#   make test-install  the package, its lintian, unit, udev rules and installed binary
#   make fuzz     libFuzzer binaries of the packet and MQTT payload parsers (clang),
#                 build/fuzz/fuzz_NAME; run
#                 one with a scratch folder first (libFuzzer writes new inputs into the first):
#                 build/fuzz/fuzz_sacn_packet -max_total_time=60 NEW/ tests/fuzz/corpus/sacn
#   make deb-arm64   build/lamprig_VERSION_arm64.deb, cross-compiled for the Pi (tools/cross/)
#   make test-arm64  the GL-free unit tests built for arm64, run under qemu user mode
#   make clean
#
# Sources are found by wildcard: every .c under render/ hal/ calib/ and firmware/ (except
# firmware/main.c) goes into the library; tools/NAME/*.c builds build/bin/lamprig-NAME;
# tests/AREA/test_NAME.c (plus tests/support/*.c) builds one test binary per area,
# build/test/test_NAME (the binary name has no sub-folder: make build/test/test_scene).

PUBLIC_TARGETS := all build test soak run bench install deb test-install test-boot fuzz \
                  test-pi5-profile
ARM64_TARGETS  := build-arm64 deb-arm64 test-arm64

ifndef LAMPRIG_INNER
# Outer make: install dependencies first, then re-enter with pkg-config available.
# The outer make runs its goals one after another: `make -j2 build/test/A build/test/B` would
# otherwise start two inner makes at once, each rebuilding the same static library (rm + ar)
# under the other's linker. Each inner make still builds in parallel (-j reaches it).
.NOTPARALLEL:
.PHONY: $(PUBLIC_TARGETS) deps clean
# A plain `make test` (as CI and the README run it) builds on every CPU: without a -j of the
# user's, the inner make gets -j(number of CPUs). MAKEFLAGS shows -j only inside a recipe.
NPROC := $(shell nproc 2>/dev/null || echo 2)
JOBS = $$(case " $$MAKEFLAGS " in *" -j"*) ;; *) echo -j$(NPROC) ;; esac)
# Each goal's wall time, build included (issue 33's target for `make test`: 15 minutes on the
# 2-core machine), printed as its last line.
$(PUBLIC_TARGETS): deps
	@t0=$$(date +%s); $(MAKE) --no-print-directory $(JOBS) LAMPRIG_INNER=1 $@; rc=$$?; \
	 echo "make $@: $$(( $$(date +%s) - t0 )) s wall, build included (status $$rc)"; exit $$rc
# The arm64 targets also install the cross toolchain and arm64 libraries (tools/deps.sh
# arm64); a native make never does.
.PHONY: $(ARM64_TARGETS) deps-arm64
$(ARM64_TARGETS): deps-arm64
	@$(MAKE) --no-print-directory $(JOBS) LAMPRIG_INNER=1 $@
deps-arm64: deps
	@sh tools/deps.sh arm64
deps:
	@sh tools/deps.sh
clean:
	rm -rf build
%: deps
	@$(MAKE) --no-print-directory $(JOBS) LAMPRIG_INNER=1 $@
else

CC      ?= cc
CXX     ?= c++
PKGS    := egl glesv2 gbm libdrm libgpiod hidapi-libusb libusb-1.0 libmodbus libpng cairo lcms2 \
           libsystemd liblo libmicrohttpd libmosquitto
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS))
PKG_LIBS   := $(shell pkg-config --libs $(PKGS))
CV_CFLAGS  := $(shell pkg-config --cflags opencv4)
# Only the OpenCV modules calib/ uses (the full list costs seconds per link).
CV_LIBS    := -lopencv_mcc -lopencv_structured_light -lopencv_calib3d -lopencv_features2d \
              -lopencv_videoio -lopencv_imgcodecs -lopencv_photo -lopencv_imgproc -lopencv_flann -lopencv_core
CMOCKA_LIBS := $(shell pkg-config --libs cmocka)

WARN    := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wno-unused-parameter
# Where presets are found when no --configs/LAMPRIG_CONFIGS is given (see render/base/paths.h).
COMMON  := -std=c11 -D_GNU_SOURCE -I. $(PKG_CFLAGS) -MMD -MP -DLR_SOURCE_CONFIGS='"$(CURDIR)/configs"'
REL_CFLAGS  := $(COMMON) $(WARN) -O2 -g
# -O2 under the sanitizers too: about 10 % off the heaviest test binaries (parity, the
# diffusion inverse), which set make test's wall time on two cores.
TEST_CFLAGS := $(COMMON) $(WARN) -Werror -O2 -g -fno-omit-frame-pointer \
               -fsanitize=address,undefined -fno-sanitize-recover=undefined
CXXFLAGS_REL  := -std=c++17 -I. -DLR_SOURCE_CONFIGS='"$(CURDIR)/configs"' $(CV_CFLAGS) -O2 -g -MMD -MP -Wall -Wextra
CXXFLAGS_TEST := -std=c++17 -I. -DLR_SOURCE_CONFIGS='"$(CURDIR)/configs"' $(CV_CFLAGS) -O1 -g -MMD -MP -Wall -Wextra -Werror \
                 -fsanitize=address,undefined -fno-sanitize-recover=undefined
LDLIBS  := -Wl,--as-needed $(PKG_LIBS) $(CV_LIBS) -lm -lpthread

LIB_C   := $(sort $(filter-out firmware/main.c, \
             $(wildcard render/*.c render/*/*.c render/*/*/*.c hal/*.c hal/*/*.c \
                        calib/*.c calib/*/*.c firmware/*.c firmware/*/*.c)))
LIB_CXX := $(sort $(wildcard calib/*.cpp calib/*/*.cpp))
TOOLS   := $(sort $(patsubst tools/%/,%,$(dir $(wildcard tools/*/*.c))))
TESTS   := $(sort $(notdir $(basename $(wildcard tests/*/test_*.c))))
SUPPORT := $(sort $(wildcard tests/support/*.c))

# The version, from one place: the VERSION file (one line), compiled into firmware/version.c
# only, so a new version rebuilds that one object.
LR_VERSION := $(shell cat VERSION 2>/dev/null || echo unknown)
VERSION_OBJ := build/obj/rel/firmware/version.o build/obj/asan/firmware/version.o
$(VERSION_OBJ): VERSION
build/obj/rel/firmware/version.o: REL_CFLAGS += -DLR_VERSION='"$(LR_VERSION)"'
build/obj/asan/firmware/version.o: TEST_CFLAGS += -DLR_VERSION='"$(LR_VERSION)"'

REL_OBJ  := $(LIB_C:%.c=build/obj/rel/%.o) $(LIB_CXX:%.cpp=build/obj/rel/%.o)
TEST_OBJ := $(LIB_C:%.c=build/obj/asan/%.o) $(LIB_CXX:%.cpp=build/obj/asan/%.o)

.PHONY: all build test soak run bench
all build: build/bin/lamprig $(TOOLS:%=build/bin/lamprig-%)

V ?= 0
Q := $(if $(filter 1,$(V)),,@)

build/obj/rel/%.o: %.c
	@mkdir -p $(@D)
	@echo "  CC      $<"
	$(Q)$(CC) $(REL_CFLAGS) -c $< -o $@
build/obj/rel/%.o: %.cpp
	@mkdir -p $(@D)
	@echo "  CXX     $<"
	$(Q)$(CXX) $(CXXFLAGS_REL) -c $< -o $@
build/obj/asan/%.o: %.c
	@mkdir -p $(@D)
	@echo "  CC-SAN  $<"
	$(Q)$(CC) $(TEST_CFLAGS) -c $< -o $@
build/obj/asan/%.o: %.cpp
	@mkdir -p $(@D)
	@echo "  CXX-SAN $<"
	$(Q)$(CXX) $(CXXFLAGS_TEST) -c $< -o $@

build/lib/liblamprig.a: $(REL_OBJ)
	@mkdir -p $(@D)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $^
build/lib/liblamprig-asan.a: $(TEST_OBJ)
	@mkdir -p $(@D)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $^

# C++ (the OpenCV shim) is linked with the C++ driver.
build/bin/lamprig: build/obj/rel/firmware/main.o build/lib/liblamprig.a
	@mkdir -p $(@D)
	@echo "  LD      $@"
	$(Q)$(CXX) -o $@ $^ $(LDLIBS)

# Keep test objects: without this make deletes them as intermediates and rebuilds each time.
.SECONDARY:
.SECONDEXPANSION:
# No '%' inside the prerequisite functions: make would substitute the stem into them.
build/bin/lamprig-%: $$(addprefix build/obj/rel/,$$(addsuffix .o,$$(basename $$(wildcard tools/$$*/*.c)))) build/lib/liblamprig.a
	@mkdir -p $(@D)
	@echo "  LD      $@"
	$(Q)$(CXX) -o $@ $^ $(LDLIBS)

# The test's source is found in whichever tests/AREA/ holds it (names are unique across areas).
build/test/test_%: $$(addprefix build/obj/asan/,$$(addsuffix .o,$$(basename $$(wildcard tests/*/test_$$*.c)))) \
                   $(SUPPORT:%.c=build/obj/asan/%.o) build/lib/liblamprig-asan.a
	@mkdir -p $(@D)
	@echo "  LD-SAN  $@"
	$(Q)$(CXX) -fsanitize=address,undefined -o $@ $^ $(LDLIBS) $(CMOCKA_LIBS)

# libFuzzer harnesses of the photometric file parsers (tests/fuzz/fuzz_ies.c, fuzz_ldt.c) with
# the render/photometry sources they need, built by clang: make build/fuzz/fuzz_ies, then
# build/fuzz/fuzz_ies -max_total_time=60 NEW/ tests/fuzz/corpus/ies (test_photometric_files
# runs the same harnesses on the corpus).
build/fuzz/fuzz_%: tests/fuzz/fuzz_%.c render/photometry/%.c render/photometry/luminaire.c \
                   render/base/err.c
	@mkdir -p $(@D)
	@echo "  FUZZ    $@"
	$(Q)clang -std=c11 -D_GNU_SOURCE -I. -g -O1 -fsanitize=fuzzer,address,undefined -o $@ $^ -lm

# The suite and the Pi 5 profile's binaries in one run (tests/run.sh's pi5: entries), the
# package's install checks beside it (their output after the run's): 45-50 s less than one
# after the other on the 2-core machine.
test: $(TESTS:%=build/test/%) build/bin/lamprig $(TOOLS:%=build/bin/lamprig-%)
	@$(MAKE) --no-print-directory test-install >build/test-install.log 2>&1 & ipid=$$!; \
	LR_PI5_GLES=$(PI5_GLES) LR_PI5_EXT="$(PI5_EXT)" sh tests/run.sh $(TESTS:%=build/test/%) \
	    $(PI5_PROFILE_TESTS:%=pi5:build/test/%); rc=$$?; \
	wait $$ipid; irc=$$?; cat build/test-install.log; \
	[ $$irc = 0 ] || echo "make test: the install checks failed (above)"; \
	[ $$rc = 0 ] && [ $$irc = 0 ]

# Render tests on llvmpipe restricted to the Raspberry Pi 5's GLES 3.1 profile
# (docs/pi5-gles31-profile.md): ES 3.1, no float blending, no 32F linear filtering, no GPU
# timers, so the renderer takes its RGBA16F maps and CPU timers. `make test` runs it in the
# suite's run: a subset (test_render_progressive, the accumulation the fallback changes, and
# test_render_passes, each pass on its own; about 42 s of CPU, 26 s wall on two cores);
# tests/run.sh prints its time.
PI5_GLES := 3.1
PI5_EXT := -GL_EXT_float_blend -GL_OES_texture_float_linear -GL_EXT_disjoint_timer_query
PI5_PROFILE_ENV := MESA_GLES_VERSION_OVERRIDE=$(PI5_GLES) MESA_EXTENSION_OVERRIDE="$(PI5_EXT)"
PI5_PROFILE_TESTS := test_render_progressive test_render_passes
.PHONY: test-pi5-profile
test-pi5-profile: $(PI5_PROFILE_TESTS:%=build/test/%)
	@$(PI5_PROFILE_ENV) sh tests/run.sh $^

# The soak of test_fw_loop at the issue's two minutes (make test runs 30 s of it; the checks
# scale with the length). LAMPRIG_SOAK_S=N make soak for another length.
soak: build/test/test_fw_loop build/bin/lamprig
	@LAMPRIG_SOAK_S=$${LAMPRIG_SOAK_S:-120} sh tests/run.sh build/test/test_fw_loop

# libFuzzer harnesses (tests/fuzz/fuzz_NAME.c) with the hal/ sources they name, built by clang
# (GCC has no libFuzzer). make test runs the same harnesses on the corpus through cmocka.
FUZZ := $(sort $(notdir $(basename $(wildcard tests/fuzz/fuzz_*.c))))
.PHONY: fuzz
fuzz: $(FUZZ:%=build/fuzz/%)
build/fuzz/fuzz_%: tests/fuzz/fuzz_%.c hal/%.c
	@mkdir -p $(@D)
	@echo "  FUZZ    $@"
	$(Q)clang -std=c11 -D_GNU_SOURCE -I. -g -O1 -fsanitize=fuzzer,address,undefined -o $@ $^
# The MQTT payload parser's harness (tests/fuzz/fuzz_mqtt_payload.c) is not one hal/ file: it
# parses with the JSON reader. Run it: build/fuzz/fuzz_mqtt_payload build/fuzz/mqtt_payload
# tests/fuzz/corpus/mqtt_payload -max_total_time=60 (new finds go to the first folder).
build/fuzz/fuzz_mqtt_payload: tests/fuzz/fuzz_mqtt_payload.c firmware/rig/mqtt_payload.c \
                              render/base/json.c render/base/json_scan.c render/base/err.c \
                              render/base/file.c
	@mkdir -p $(@D) build/fuzz/mqtt_payload
	@echo "  FUZZ    $@"
	$(Q)clang -std=c11 -D_GNU_SOURCE -I. -g -O1 -fsanitize=fuzzer,address,undefined \
	    -fno-sanitize-recover=undefined -o $@ $^ -lm

# ---- install, package ----
# The layout paths.h looks for: BINDIR/lamprig finds BINDIR/../share/lamprig/{configs,shaders}
# (so keep BINDIR and DATADIR under one PREFIX, or set LAMPRIG_CONFIGS/LAMPRIG_SHADERS).
PREFIX      ?= /usr/local
BINDIR      ?= $(PREFIX)/bin
DATADIR     ?= $(PREFIX)/share/lamprig
MANDIR      ?= $(PREFIX)/share/man
SYSCONFDIR  ?= $(if $(filter /usr,$(PREFIX)),/etc,$(PREFIX)/etc)
UNITDIR     ?= $(PREFIX)/lib/systemd/system
# udev reads rules only from /etc, /run and /usr/lib (/lib): not from /usr/local.
UDEVDIR     ?= $(if $(filter /usr,$(PREFIX)),$(PREFIX)/lib/udev/rules.d,/etc/udev/rules.d)
SYSUSERSDIR ?= $(PREFIX)/lib/sysusers.d
STATEDIR    ?= /var/lib/lamprig
INSTALL_BINS := lamprig lamprig-modbus-sim
# Every data file the program reads: what git tracks under configs/ (never a user's stray file
# in the checkout), less configs/bench/references (they serve `make bench` only) and the
# folders' READMEs. The planner reads bench/front.csv and bench/models.csv (the change costs
# behind quality.change_ms). Outside a git checkout (a release tarball) the same by wildcard.
DATA_GIT    := $(shell git ls-files configs 2>/dev/null)
DATA_FILES  := $(sort $(filter-out configs/bench/references/% %.md, \
                 $(if $(DATA_GIT),$(wildcard $(DATA_GIT)),$(wildcard configs/*/*))))
SHADER_FILES := $(sort $(wildcard render/shaders/* render/shaders/*/*))
SUBST = sed -e 's|@BINDIR@|$(BINDIR)|g' -e 's|@DATADIR@|$(DATADIR)|g' \
            -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g' -e 's|@STATEDIR@|$(STATEDIR)|g'

.PHONY: install deb test-install test-boot
# INSTALL_FROM: where the binaries come from (deb-arm64 installs build/arm64/bin's).
INSTALL_FROM ?= build/bin
install: $(INSTALL_BINS:%=$(INSTALL_FROM)/%)
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(DATADIR) $(DESTDIR)$(MANDIR)/man1 \
	    $(DESTDIR)$(SYSCONFDIR)/lamprig $(DESTDIR)$(UNITDIR) $(DESTDIR)$(UDEVDIR) \
	    $(DESTDIR)$(SYSUSERSDIR)
	install -m 0755 $(INSTALL_BINS:%=$(INSTALL_FROM)/%) $(DESTDIR)$(BINDIR)/
	@echo "  INSTALL configs, shaders -> $(DESTDIR)$(DATADIR)"
	@for f in $(DATA_FILES); do \
	    [ -f "$$f" ] && install -D -m 0644 "$$f" "$(DESTDIR)$(DATADIR)/$$f" || exit 1; done
	@for f in $(SHADER_FILES); do [ -d "$$f" ] || \
	    install -D -m 0644 "$$f" "$(DESTDIR)$(DATADIR)/shaders/$${f#render/shaders/}" || exit 1; done
	install -m 0644 $(INSTALL_BINS:%=tools/install/%.1) $(DESTDIR)$(MANDIR)/man1/
	$(SUBST) tools/install/lamprig.service.in > $(DESTDIR)$(UNITDIR)/lamprig.service
	install -m 0644 tools/install/60-lamprig.rules $(DESTDIR)$(UDEVDIR)/60-lamprig.rules
	install -m 0644 tools/install/sysusers.conf $(DESTDIR)$(SYSUSERSDIR)/lamprig.conf
	@# Discovery (_lamprig._tcp), announced only once linked into /etc/avahi/services.
	install -d $(DESTDIR)$(DATADIR)/avahi
	$(SUBST) tools/install/lamprig-avahi.service > $(DESTDIR)$(DATADIR)/avahi/lamprig.service
	chmod 0644 $(DESTDIR)$(DATADIR)/avahi/lamprig.service
	@# An existing rig config is the user's: never overwritten.
	[ -e $(DESTDIR)$(SYSCONFDIR)/lamprig/rig.json ] || \
	    $(SUBST) tools/install/rig.json.in > $(DESTDIR)$(SYSCONFDIR)/lamprig/rig.json
	chmod 0644 $(DESTDIR)$(UNITDIR)/lamprig.service $(DESTDIR)$(SYSCONFDIR)/lamprig/rig.json

# Debian 12 puts units and udev rules under /lib (lintian expects them there).
deb: $(INSTALL_BINS:%=build/bin/%)
	rm -rf build/deb
	$(MAKE) --no-print-directory install DESTDIR=$(CURDIR)/build/deb/root PREFIX=/usr \
	    UNITDIR=/lib/systemd/system UDEVDIR=/lib/udev/rules.d SYSUSERSDIR=/usr/lib/sysusers.d
	sh tools/debian/build-deb.sh build/deb build

test-install: deb
	sh tests/install.sh build

# The package under a booted systemd: debootstrap root + apt + systemd-nspawn --boot (root;
# .ci/run runs it after make test). Starts, renders, reloads, stops; the sandbox's score.
test-boot: deb
	sh tests/boot.sh build

# 8 progressive frames (the scene converges at 64): about a minute on llvmpipe; leave out
# --frames to render until render.frames are accumulated. --no-plan: the demo shows the scene
# file's own settings; the candle's 0.05 budget is below the model's measured bias, and the
# plan's closest setting (32^2 maps, N 4) looks blotchy (render/plan/README.md).
run: build/bin/lamprig
	@mkdir -p build/out
	./build/bin/lamprig plan --scene configs/scenes/candle.json
	./build/bin/lamprig render --scene configs/scenes/candle.json --frames 8 --plan-models \
	    --out build/out/candle.png --hdr build/out/candle.pfm --stats build/out/candle-stats.json

bench: build/bin/lamprig $(TOOLS:%=build/bin/lamprig-%)
	./build/bin/lamprig-bench

# arm64: make deb-arm64, make test-arm64 (tools/cross/arm64.mk).
include tools/cross/arm64.mk

-include $(shell find build/obj build/arm64/obj -name '*.d' 2>/dev/null)
endif
