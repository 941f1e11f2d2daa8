# SPDX-License-Identifier: BSD-3-Clause
# install.mk - `make install PREFIX=/usr/local DESTDIR=` (issue 23): for hosts (a ROS 2 node, a
# companion-computer service). Firmware does not install: it includes src/sources.mk
# (port/baremetal/README).
#   $(LIBDIR)        libocc.a, libocc.so.$(OCC_VERSION) (+ libocc.so.0, libocc.so links),
#                    libocc_posix.a (the POSIX port: what include/occmap/host/ declares)
#   $(INCLUDEDIR)    occmap/*.h (portable), occmap/host/*.h (hosts)
#   $(BINDIR)        occmap
#   $(PREFIX)/share/occmap/view  the scripts occmap view inlines (if `make view-assets` ran)
#   $(LIBDIR)/pkgconfig/occmap.pc, occmap-host.pc
#   $(LIBDIR)/cmake/occmap/occmapConfig.cmake, occmapConfigVersion.cmake: occmap::occmap
#                    (static), occmap::occmap_shared, occmap::host
# `make uninstall` with the same PREFIX and DESTDIR removes exactly these files.
OCC_VERSION := 0.1.0
OCC_SOVERSION := 0
PREFIX ?= /usr/local
DESTDIR ?=
BINDIR ?= $(PREFIX)/bin
LIBDIR ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
INSTALL ?= install
APT_PKGS += pkg-config cmake

$(BUILD)/libocc_posix.a: $(PORT_SRC:%.c=$(BUILD)/relhost/%.o)
	@rm -f $@
	$(AR) rcs $@ $^

# The pointer size of the library's compiler (the CMake version file refuses other consumers).
INSTALL_PTR_BYTES = $(shell printf '' | $(CC) -dM -E - | sed -n 's/^\#define __SIZEOF_POINTER__ //p')
# The templates' @...@ fields; the CMake files find the prefix relative to their own folder.
INSTALL_SUBST = sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@LIBDIR@|$(LIBDIR)|g' \
  -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|g' -e 's|@VERSION@|$(OCC_VERSION)|g' \
  -e 's|@SOVERSION@|$(OCC_SOVERSION)|g' -e 's|@SIZEOF_VOID_P@|$(INSTALL_PTR_BYTES)|g' \
  -e 's|@SIZEOF_VOID_P_BITS@|$(shell echo $$(( $(INSTALL_PTR_BYTES) * 8 )))|g' \
  -e 's|@REL_PREFIX@|$(shell realpath -m --relative-to=$(LIBDIR)/cmake/occmap $(PREFIX))|g' \
  -e 's|@REL_LIBDIR@|$(shell realpath -m --relative-to=$(PREFIX) $(LIBDIR))|g' \
  -e 's|@REL_INCLUDEDIR@|$(shell realpath -m --relative-to=$(PREFIX) $(INCLUDEDIR))|g'
INSTALL_SO := libocc.so.$(OCC_VERSION)
# occmap view's scripts (tools/view.mk), when they were fetched: the installed tool looks for
# them in PREFIX/share/occmap/view (tools/cmd_view.c).
VIEW_SHARE = $(PREFIX)/share/occmap/view
VIEW_FILES := three.min.js OrbitControls.js view_app.js LICENSE.three
INSTALL_FILES = $(BINDIR)/occmap $(LIBDIR)/libocc.a $(LIBDIR)/libocc_posix.a $(LIBDIR)/$(INSTALL_SO) \
  $(LIBDIR)/libocc.so.$(OCC_SOVERSION) $(LIBDIR)/libocc.so $(LIBDIR)/pkgconfig/occmap.pc \
  $(LIBDIR)/pkgconfig/occmap-host.pc $(LIBDIR)/cmake/occmap/occmapConfig.cmake \
  $(LIBDIR)/cmake/occmap/occmapConfigVersion.cmake $(VIEW_FILES:%=$(VIEW_SHARE)/%) \
  $(patsubst include/%,$(INCLUDEDIR)/%,$(wildcard include/occmap/*.h include/occmap/host/*.h))

install: $(BUILD)/libocc.a $(BUILD)/libocc.so $(BUILD)/libocc_posix.a $(BUILD)/occmap
	@case "$(PREFIX)" in /*) ;; *) echo "install: PREFIX must be absolute (got '$(PREFIX)')"; exit 2;; esac
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(LIBDIR)/cmake/occmap \
	  $(DESTDIR)$(INCLUDEDIR)/occmap/host
	$(INSTALL) -m 755 $(BUILD)/occmap $(DESTDIR)$(BINDIR)/occmap
	$(INSTALL) -m 644 $(BUILD)/libocc.a $(BUILD)/libocc_posix.a $(DESTDIR)$(LIBDIR)/
	$(INSTALL) -m 755 $(BUILD)/libocc.so $(DESTDIR)$(LIBDIR)/$(INSTALL_SO)
	ln -sf $(INSTALL_SO) $(DESTDIR)$(LIBDIR)/libocc.so.$(OCC_SOVERSION)
	ln -sf libocc.so.$(OCC_SOVERSION) $(DESTDIR)$(LIBDIR)/libocc.so
	$(INSTALL) -m 644 include/occmap/*.h $(DESTDIR)$(INCLUDEDIR)/occmap/
	$(INSTALL) -m 644 include/occmap/host/*.h $(DESTDIR)$(INCLUDEDIR)/occmap/host/
	$(INSTALL_SUBST) port/install/occmap.pc.in > $(DESTDIR)$(LIBDIR)/pkgconfig/occmap.pc
	$(INSTALL_SUBST) port/install/occmap-host.pc.in > $(DESTDIR)$(LIBDIR)/pkgconfig/occmap-host.pc
	$(INSTALL_SUBST) port/install/occmapConfig.cmake.in > $(DESTDIR)$(LIBDIR)/cmake/occmap/occmapConfig.cmake
	$(INSTALL_SUBST) port/install/occmapConfigVersion.cmake.in \
	  > $(DESTDIR)$(LIBDIR)/cmake/occmap/occmapConfigVersion.cmake
	@if [ -r $(VIEW_ASSETS)/three.min.js ]; then \
	  echo "$(INSTALL) -m 644 $(VIEW_FILES:%=$(VIEW_ASSETS)/%) $(DESTDIR)$(VIEW_SHARE)/"; \
	  $(INSTALL) -d $(DESTDIR)$(VIEW_SHARE) && \
	  $(INSTALL) -m 644 $(VIEW_FILES:%=$(VIEW_ASSETS)/%) $(DESTDIR)$(VIEW_SHARE)/; \
	else echo "install: no $(VIEW_ASSETS) (make view-assets): the installed occmap view needs --assets"; fi

uninstall:
	rm -f $(addprefix $(DESTDIR),$(INSTALL_FILES))
	-rmdir $(DESTDIR)$(INCLUDEDIR)/occmap/host $(DESTDIR)$(INCLUDEDIR)/occmap \
	  $(DESTDIR)$(LIBDIR)/cmake/occmap $(DESTDIR)$(VIEW_SHARE) $(DESTDIR)$(PREFIX)/share/occmap 2>/dev/null

.PHONY: install uninstall
