# arm64 (Raspberry Pi 5 class board) cross build, included by the Makefile's inner make.
#
#   make deb-arm64   build/arm64/bin/* for aarch64 and build/lamprig_VERSION_arm64.deb
#   make test-arm64  the GL-free unit tests built for aarch64, run under qemu user mode
#
# Everything goes under build/arm64/: the native build (build/obj, build/bin) is never touched.
# The toolchain is Debian's cross one (crossbuild-essential-arm64), the libraries the arm64
# multiarch -dev packages (tools/deps.sh, ARM64_PKGS: installed only by these targets).
#
# OpenCV: Debian 12's arm64 libopencv-dev (the metapackage, not Multi-Arch: same) cannot sit
# beside the native one, and the per-module packages for calib3d, features2d, imgcodecs,
# videoio and contrib (mcc, structured_light) pull arm64 GDAL/GTK packages that would remove
# the native OpenCV. So core, imgproc, flann and photo come from their arm64 -dev packages and
# the other five modules' arm64 runtime packages are fetched with `apt-get download` and
# unpacked under build/arm64/cv/ (nothing installed): the linker takes their .so files from
# there without their own dependencies (-rpath-link is not enough, hence
# --allow-shlib-undefined: those symbols are resolved on the board, where the package's
# Depends installs the libraries), and dpkg-shlibdeps reads their shlibs/symbols from the
# unpacked control files (-S). The headers are arch-independent except cvconfig.h, which the
# arm64 libopencv-core-dev ships under /usr/include/aarch64-linux-gnu/opencv4.

ARM64_TRIPLET := aarch64-linux-gnu
ARM64_CC      := $(ARM64_TRIPLET)-gcc
ARM64_CXX     := $(ARM64_TRIPLET)-g++
ARM64_AR      := $(ARM64_TRIPLET)-ar
ARM64_PC      := PKG_CONFIG_LIBDIR=/usr/lib/$(ARM64_TRIPLET)/pkgconfig:/usr/share/pkgconfig \
                 PKG_CONFIG_SYSROOT_DIR= pkg-config
ARM64_CV_DEBS := libopencv-calib3d406 libopencv-features2d406 libopencv-imgcodecs406 \
                 libopencv-videoio406 libopencv-contrib406
ARM64_CV      := build/arm64/cv

# Evaluated only when an arm64 target runs (recursive '=' variables): a native make never
# calls the arm64 pkg-config.
# liblo has no arm64 .pc (liblo-dev is not Multi-Arch: same, tools/deps.sh): its headers are
# the native ones (no -I needed), the library liblo7:arm64's by its soname.
ARM64_PKG_CFLAGS = $(shell $(ARM64_PC) --cflags $(filter-out liblo,$(PKGS)))
ARM64_PKG_LIBS   = $(shell $(ARM64_PC) --libs $(filter-out liblo,$(PKGS))) -l:liblo.so.7
ARM64_CV_CFLAGS := -I/usr/include/$(ARM64_TRIPLET)/opencv4 -I/usr/include/opencv4
ARM64_COMMON     = -std=c11 -D_GNU_SOURCE -I. $(ARM64_PKG_CFLAGS) -MMD -MP \
                   -DLR_SOURCE_CONFIGS='"$(CURDIR)/configs"'
ARM64_CFLAGS     = $(ARM64_COMMON) $(WARN) -Werror -O2 -g
ARM64_CXXFLAGS  := -std=c++17 -I. -DLR_SOURCE_CONFIGS='"$(CURDIR)/configs"' $(ARM64_CV_CFLAGS) \
                   -O2 -g -MMD -MP -Wall -Wextra -Werror
ARM64_LDLIBS     = -Wl,--as-needed $(ARM64_PKG_LIBS) -L$(ARM64_CV)/lib -Wl,--allow-shlib-undefined \
                   $(CV_LIBS) -lm -lpthread

ARM64_OBJ := $(LIB_C:%.c=build/arm64/obj/%.o) $(LIB_CXX:%.cpp=build/arm64/obj/%.o)
ARM64_BINS := build/arm64/bin/lamprig $(TOOLS:%=build/arm64/bin/lamprig-%)
build/arm64/obj/firmware/version.o: VERSION
build/arm64/obj/firmware/version.o: ARM64_CFLAGS += -DLR_VERSION='"$(LR_VERSION)"'

# The five OpenCV modules without a co-installable arm64 -dev package (see above): the .debs
# of the version of the installed arm64 libopencv-core406, unpacked with their control files, and the
# unversioned .so names the linker looks for.
$(ARM64_CV)/.stamp:
	@mkdir -p $(ARM64_CV)/debs $(ARM64_CV)/lib $(ARM64_CV)/pkg
	@echo "  FETCH   arm64 OpenCV modules: $(ARM64_CV_DEBS)"
	$(Q)cd $(ARM64_CV)/debs && rm -f *.deb && apt-get download -q \
	    $(foreach p,$(ARM64_CV_DEBS),$(p):arm64=$$(dpkg-query -W -f='$${Version}' libopencv-core406:arm64))
	$(Q)for d in $(ARM64_CV)/debs/*.deb; do \
	    p=$$(basename $$d | cut -d_ -f1); rm -rf $(ARM64_CV)/pkg/$$p; \
	    dpkg-deb -R $$d $(ARM64_CV)/pkg/$$p || exit 1; done
	$(Q)for s in $(ARM64_CV)/pkg/*/usr/lib/$(ARM64_TRIPLET)/libopencv_*.so.4.*; do \
	    b=$$(basename $$s); ln -sf $(CURDIR)/$$s $(ARM64_CV)/lib/$${b%%.so.*}.so; done
	@touch $@

build/arm64/obj/%.o: %.c
	@mkdir -p $(@D)
	@echo "  CC-A64  $<"
	$(Q)$(ARM64_CC) $(ARM64_CFLAGS) -c $< -o $@
build/arm64/obj/%.o: %.cpp
	@mkdir -p $(@D)
	@echo "  CXX-A64 $<"
	$(Q)$(ARM64_CXX) $(ARM64_CXXFLAGS) -c $< -o $@
build/arm64/lib/liblamprig.a: $(ARM64_OBJ)
	@mkdir -p $(@D)
	@echo "  AR-A64  $@"
	$(Q)rm -f $@ && $(ARM64_AR) rcs $@ $^
build/arm64/bin/lamprig: build/arm64/obj/firmware/main.o build/arm64/lib/liblamprig.a $(ARM64_CV)/.stamp
	@mkdir -p $(@D)
	@echo "  LD-A64  $@"
	$(Q)$(ARM64_CXX) -o $@ $(filter %.o %.a,$^) $(ARM64_LDLIBS)
build/arm64/bin/lamprig-%: $$(addprefix build/arm64/obj/,$$(addsuffix .o,$$(basename $$(wildcard tools/$$*/*.c)))) \
                           build/arm64/lib/liblamprig.a $(ARM64_CV)/.stamp
	@mkdir -p $(@D)
	@echo "  LD-A64  $@"
	$(Q)$(ARM64_CXX) -o $@ $(filter %.o %.a,$^) $(ARM64_LDLIBS)

.PHONY: build-arm64 deb-arm64 test-arm64
build-arm64: $(ARM64_BINS)

# The same staged install as `make deb`, from build/arm64/bin, packaged for arm64:
# dpkg-architecture -aarm64 gives build-deb.sh the host arch (dpkg-shlibdeps searches the
# arm64 multiarch library paths, dpkg-gencontrol writes Architecture: arm64) and the cross strip.
# Every tool is cross-built too (build-arm64), the package holds INSTALL_BINS as `make deb` does.
deb-arm64: $(ARM64_BINS)
	rm -rf build/arm64/deb
	$(MAKE) --no-print-directory install DESTDIR=$(CURDIR)/build/arm64/deb/root PREFIX=/usr \
	    UNITDIR=/lib/systemd/system UDEVDIR=/lib/udev/rules.d SYSUSERSDIR=/usr/lib/sysusers.d \
	    INSTALL_FROM=build/arm64/bin
	CC=$(ARM64_CC) STRIP=$(ARM64_TRIPLET)-strip \
	LR_SHLIBDEPS_ARGS="$(foreach d,$(wildcard $(ARM64_CV)/pkg/*),-S$(CURDIR)/$(d))" \
	    dpkg-architecture -aarm64 -c sh tools/debian/build-deb.sh build/arm64/deb build
	sh tests/arm64/check-deb.sh build/lamprig_$(LR_VERSION)_arm64.deb

# ---- tests on arm64, under qemu user mode ----
# The GL-free unit tests of the areas the issue names, one or two binaries each, built for
# aarch64 and run by tests/run.sh through qemu-aarch64-static (LR_TEST_EXEC; the arm64
# dynamic loader and libraries are the multiarch ones under /usr/lib/aarch64-linux-gnu, so
# no -L sysroot is needed). UBSan but no ASan: ASan's fixed shadow mapping needs the host's
# 47-bit layout that qemu's guest address space does not give reliably, and it would cost
# another 2-3x on an emulator already 5-10x slower than the host; make test runs the same
# tests under ASan natively. UBSan (-fno-sanitize-recover) still stops on undefined
# behaviour that only shows on arm64 (misaligned loads, shifts and overflow where arm64's
# unsigned char or long double differ); the tests' own tolerances check the arithmetic.
# Left out for time: test_optics_multipole and test_transrad ran over 10 minutes each under
# qemu on the 2-core CI machine (15 s and 45 s natively under ASan). Left out because they
# reach OpenCV: test_calib_files (its failed-calibration and `calib check` cases run the
# Gray-code and camera calibration; they failed on cv_absent.c's error, as designed).
ARM64_TESTS := test_optics_dipole test_json test_scene test_mesh \
               test_hal_dmx_packet test_hal_sim test_control test_diffusion
ARM64_TFLAGS = $(ARM64_COMMON) $(WARN) -Werror -O1 -g -fno-omit-frame-pointer \
               -fsanitize=undefined -fno-sanitize-recover=undefined
# calib/cv_shim.cpp is replaced by tests/arm64/cv_absent.c (it says why): the test binaries
# link only the libraries installed for arm64, and libubsan statically (the cross runtime
# lives under /usr/aarch64-linux-gnu/lib, outside the loader's multiarch paths).
ARM64_TOBJ := $(LIB_C:%.c=build/arm64/tobj/%.o) build/arm64/tobj/tests/arm64/cv_absent.o
build/arm64/tobj/firmware/version.o: VERSION
build/arm64/tobj/firmware/version.o: ARM64_TFLAGS += -DLR_VERSION='"$(LR_VERSION)"'
build/arm64/tobj/%.o: %.c
	@mkdir -p $(@D)
	@echo "  CC-A64T $<"
	$(Q)$(ARM64_CC) $(ARM64_TFLAGS) -c $< -o $@
build/arm64/lib/liblamprig-ubsan.a: $(ARM64_TOBJ)
	@mkdir -p $(@D)
	@echo "  AR-A64  $@"
	$(Q)rm -f $@ && $(ARM64_AR) rcs $@ $^
build/arm64/test/test_%: $$(addprefix build/arm64/tobj/,$$(addsuffix .o,$$(basename $$(wildcard tests/*/test_$$*.c)))) \
                         $(SUPPORT:%.c=build/arm64/tobj/%.o) build/arm64/lib/liblamprig-ubsan.a
	@mkdir -p $(@D)
	@echo "  LD-A64T $@"
	$(Q)$(ARM64_CXX) -fsanitize=undefined -static-libubsan -o $@ $^ -Wl,--as-needed $(ARM64_PKG_LIBS) \
	    -lm -lpthread $(shell $(ARM64_PC) --libs cmocka)

# Prints each binary's time and the total (tests/run.sh).
test-arm64: $(ARM64_TESTS:%=build/arm64/test/%)
	@start=$$(date +%s); LR_TEST_EXEC=qemu-aarch64-static sh tests/run.sh $^; rc=$$?; \
	    echo "test-arm64: $(words $^) arm64 binaries under qemu in $$(( $$(date +%s) - start )) s"; exit $$rc
