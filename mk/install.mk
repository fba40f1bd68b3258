# make install [PREFIX=/usr/local] [DESTDIR=] [SYSCONFDIR=]: what a machine
# needs to build its PLC projects and start one at boot (docs/install.md):
#   PREFIX/bin/            stc, plcrt-build, plctrace
#   PREFIX/lib/plcrt/      the runtime's objects and headers, from which
#                          plcrt-build links a project's plcrt; parts.sh
#                          (where everything lies); plcrt-start
#   PREFIX/share/stc/include   the headers stc's C needs
#   PREFIX/share/plcrt/    the library: st/ sources, epicpos.st, the TC6-XML
#                          exports, the C-bodied blocks; the examples
#   PREFIX/share/doc/plcrt the docs
#   SYSCONFDIR/plcrt/plcrt.ini   a sample configuration (kept if present)
#   UNITDIR/plcrt@.service the systemd unit (dist/plcrt@.service)
# make deb: the same as a Debian package, build/deb/plcrt_VERSION_ARCH.deb
# (PREFIX=/usr, SYSCONFDIR=/etc), with dpkg-deb.
PREFIX     ?= /usr/local
SYSCONFDIR ?= $(if $(filter /usr,$(PREFIX)),/etc,$(PREFIX)/etc)
UNITDIR    ?= $(PREFIX)/lib/systemd/system
LIBDIR      = $(PREFIX)/lib/plcrt
DATADIR     = $(PREFIX)/share/plcrt
DOCDIR      = $(PREFIX)/share/doc/plcrt
INST_B      = $(BUILD)/install$(subst /,_,$(PREFIX))
DEB_VERSION ?= $(STC_VERSION_STR)
STC_VERSION_STR := $(shell sed -n 's/^#define STC_VERSION "\(.*\)"/\1/p' stc/stc.h)
INST_OBJS   = $(PLCRT_MAIN) $(PLCRT_OBJ)

.PHONY: install deb

# stc again, its include folder the installed one
$(INST_B)/stc-main.o: stc/main.c stc/stc.h
	@mkdir -p $(@D)
	$(call say,CC,$< (installed paths))
	$(Q)$(CC) $(CFLAGS) -DSTC_INCLUDE_DIR='"$(PREFIX)/share/stc/include"' -c -o $@ $<
$(INST_B)/stc: $(INST_B)/stc-main.o $(filter-out $(BUILD)/stc/main.o,$(STC_OBJS))
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lm

# where plcrt-build finds everything once installed
$(INST_B)/parts.sh: $(MAKEFILE_LIST)
	@mkdir -p $(@D)
	@{ echo "STC='$(PREFIX)/bin/stc'"; echo "STC_BIN='$(PREFIX)/bin/stc'"; \
	   echo "STC_INC='$(PREFIX)/share/stc/include'"; \
	   echo "ST_LIB_SRC='$(addprefix $(DATADIR)/,$(ST_LIB_SRC))'"; \
	   echo "GEN_PROGRAM='$(LIBDIR)/gen_program.sh'"; echo "RT_INC='$(LIBDIR)/include'"; \
	   echo "CC='$(CC)'"; echo "CFLAGS='$(CFLAGS)'"; echo "GEN_CFLAGS='$(PLC_GEN_CFLAGS)'"; \
	   echo "OBJS='$(addprefix $(LIBDIR)/obj/,$(notdir $(INST_OBJS)))'"; echo "LIBS='$(PLCRT_LIBS)'"; \
	   echo "RUN_FG='$(LIBDIR)/run_fg.sh'"; \
	 } > $@

$(INST_B)/plcrt@.service: dist/plcrt@.service
	@mkdir -p $(@D)
	@sed 's|@LIBDIR@|$(LIBDIR)|g; s|@DOCDIR@|$(DOCDIR)|g' $< > $@

install: $(INST_B)/stc $(INST_B)/parts.sh $(INST_B)/plcrt@.service $(INST_OBJS) $(ST_LIB) $(ST_LIB_XML) $(C_BLOCKS_XML)
	$(call say,INST,$(DESTDIR)$(PREFIX))
	$(Q)install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(LIBDIR)/obj $(DESTDIR)$(LIBDIR)/include \
	    $(DESTDIR)$(PREFIX)/share/stc/include $(DESTDIR)$(DATADIR)/c_blocks $(DESTDIR)$(DOCDIR) \
	    $(DESTDIR)$(SYSCONFDIR)/plcrt $(DESTDIR)$(UNITDIR)
	$(Q)install -m 755 $(INST_B)/stc $(DESTDIR)$(PREFIX)/bin/stc
	$(Q)install -m 755 plcrt-build plc_runtime/plctrace $(DESTDIR)$(PREFIX)/bin/
	$(Q)install -m 644 $(INST_OBJS) $(DESTDIR)$(LIBDIR)/obj/
	$(Q)install -m 644 plc_runtime/*.h c_blocks/plant.h $(DESTDIR)$(LIBDIR)/include/
	$(Q)install -m 644 $(INST_B)/parts.sh $(DESTDIR)$(LIBDIR)/parts.sh
	$(Q)install -m 755 plc_runtime/gen_program.sh mk/run_fg.sh dist/plcrt-start $(DESTDIR)$(LIBDIR)/
	$(Q)cp -R stc/include/. $(DESTDIR)$(PREFIX)/share/stc/include/
	$(Q)for f in $(ST_LIB_SRC); do install -D -m 644 $$f $(DESTDIR)$(DATADIR)/$$f; done
	$(Q)install -m 644 $(ST_LIB) $(ST_LIB_XML) $(DESTDIR)$(DATADIR)/
	$(Q)install -m 644 $(C_BLOCKS_ST) $(C_BLOCKS_XML) c_blocks/plant.c c_blocks/plant.h $(DESTDIR)$(DATADIR)/c_blocks/
	$(Q)cp -R examples $(DESTDIR)$(DATADIR)/ && rm -f $(DESTDIR)$(DATADIR)/examples/part.mk
	$(Q)install -m 644 README.md docs/*.md $(DESTDIR)$(DOCDIR)/
	$(Q)[ -e $(DESTDIR)$(SYSCONFDIR)/plcrt/plcrt.ini ] || install -m 644 dist/plcrt.ini $(DESTDIR)$(SYSCONFDIR)/plcrt/plcrt.ini
	$(Q)install -m 644 $(INST_B)/plcrt@.service $(DESTDIR)$(UNITDIR)/plcrt@.service

# The Debian package: the install above under PREFIX=/usr into a staging
# root, a control file, dpkg-deb. Depends: what plcrt-build needs to link a
# project's plcrt and what plctrace runs on.
DEB_ARCH  = $(shell dpkg --print-architecture 2>/dev/null || echo amd64)
DEB_ROOT  = $(BUILD)/deb/root
DEB_FILE  = $(BUILD)/deb/plcrt_$(DEB_VERSION)_$(DEB_ARCH).deb
deb:
	@rm -rf $(DEB_ROOT) && mkdir -p $(DEB_ROOT)/DEBIAN
	@$(MAKE) --no-print-directory install PREFIX=/usr SYSCONFDIR=/etc UNITDIR=/lib/systemd/system DESTDIR=$(abspath $(DEB_ROOT))
	@{ echo "Package: plcrt"; echo "Version: $(DEB_VERSION)"; echo "Architecture: $(DEB_ARCH)"; \
	   echo "Maintainer: motion-plc developers <motion-plc@localhost>"; \
	   echo "Section: misc"; echo "Priority: optional"; \
	   echo "Depends: gcc, make, libc6-dev, libinih-dev, libmodbus-dev, python3, python3-matplotlib"; \
	   echo "Recommends: python3-pymodbus, mbpoll"; \
	   echo "Installed-Size: $$(du -sk $(DEB_ROOT) | cut -f1)"; \
	   echo "Description: soft-PLC runtime, Structured Text compiler and motion library"; \
	   echo " plcrt runs IEC 61131-3 programs compiled by stc (or matiec) cyclically,"; \
	   echo " with a Modbus TCP/RTU server, CANopen master and trace; plcrt-build links"; \
	   echo " a project's plcrt; plcrt@.service starts a project at boot."; \
	 } > $(DEB_ROOT)/DEBIAN/control
	@echo /etc/plcrt/plcrt.ini > $(DEB_ROOT)/DEBIAN/conffiles
	$(call say,DEB,$(DEB_FILE))
	$(Q)dpkg-deb --root-owner-group --build $(DEB_ROOT) $(DEB_FILE) >/dev/null
