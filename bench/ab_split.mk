# SPDX-License-Identifier: BSD-3-Clause
# ab_split.mk - `make bench-ab-split` (in neither `make test` nor `make bench`): the library as
# of AB_BASE (default: main as the last stop landed it) against this tree's, linked
# into one program (bench/ab_split.cpp) with the old library's symbols renamed old_*, run in
# interleaved rounds on scan.dat (SIMPLE, DISCRETE, super rays at 0.1 / 0.05 m), the 10 TUM
# pioneer frames (SIMPLE, DISCRETE at 0.05 m; PROJECTIVE through occ_map_insert_depth, the
# `proj` case) and geb079.bt (castRay, line of sight, collision).
# Proves a refactor of a hot path costs nothing: `make bench-ab-split AB_BASE=<commit>`; AB_ARGS
# passes options (e.g. AB_ARGS='--inserts-only --case simple'; AB_ARGS=--lookup-only times the
# lookup index on geb079.bt and on fr_079 from ../shared/data/maps when present).
AB_BASE ?= 72c2fec
AB_DIR := $(BUILD)/ab
AB_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
AB_TUM := ../shared/data/depth/tum_fr2_pioneer_slam2
AB_FR079 := $(wildcard ../shared/data/maps/fr_079_t1_model.ot)
# The map modules and sensors (occ_map_insert_depth), no other front end, with the release
# build's flags (REL_OPT; PROJ_VEC_CFLAGS on the projective files). Rebuilt when AB_BASE names
# another commit or those flags change (kept in $(AB_DIR)/base). Where the code lands differs
# between the halves: the same commit on both sides measured PROJECTIVE 0.96 to 1.02, and even
# both halves built alike from one tree (the Makefile with BUILD=<dir>, one renamed) 1.01 and
# 1.04: a change smaller than about 4 % needs repeated runs and an instruction count (callgrind)
# beside the times.
$(AB_DIR)/libocc_old.a: FORCE_AB
	@set -e; sha=$$(git rev-parse --verify '$(AB_BASE)^{commit}'); \
	if [ -f $@ ] && [ "$$(cat $(AB_DIR)/base 2>/dev/null)" = "$$sha $(REL_OPT) $(PROJ_VEC_CFLAGS) sensors" ]; then exit 0; fi; \
	echo "ab: building the library at $(AB_BASE) ($$sha) as old_*"; \
	rm -rf $(AB_DIR)/old && mkdir -p $(AB_DIR)/old; \
	git archive "$$sha" src include | tar -x -C $(AB_DIR)/old; \
	cd $(AB_DIR)/old; objs=""; \
	for f in $$(for m in $(OCC_MAP_MODULES) sensors; do [ ! -d src/$$m ] || find src/$$m -name '*.c'; done | \
	           grep -v collide_ccd.c | sort); do \
	  o=obj/$${f%.c}.o; mkdir -p $$(dirname $$o); \
	  case $$f in src/integrate/projective*) fl='$(PROJ_VEC_CFLAGS)';; *) fl='';; esac; \
	  $(CC) $(WARN) $(REL_OPT) -g $$fl -Iinclude -Isrc -c $$f -o $$o; objs="$$objs $$o"; \
	done; \
	rm -f lib.a; $(AR) rcs lib.a $$objs; \
	nm -g --defined-only --format=posix lib.a | \
	  awk 'NF >= 2 && $$2 ~ /^[A-Z]$$/ {print $$1 " old_" $$1}' | sort -u > rename.txt; \
	objcopy --redefine-syms=rename.txt lib.a ../libocc_old.a; \
	cd - > /dev/null; echo "$$sha $(REL_OPT) $(PROJ_VEC_CFLAGS) sensors" > $(AB_DIR)/base
$(BUILD)/bench/ab_split: bench/ab_split.cpp $(BUILD)/relhost/port/posix/file_io.o \
    $(patsubst %,$(BUILD)/relhost/port/posix/%.o,scan_xyz scan_graph depth_png) \
    $(BUILD)/libocc.a $(AB_DIR)/libocc_old.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $^ -lccd -lpng -lm
bench-ab-split: $(BUILD)/bench/ab_split $(BUILD)/data/scan.dat
	./$(BUILD)/bench/ab_split --rounds $(or $(AB_ROUNDS),15) --tum $(AB_TUM) \
	  $(if $(AB_FR079),--fr079 $(AB_FR079)) $(AB_ARGS) \
	  $(BUILD)/data/scan.dat $(AB_MAP)
.PHONY: bench-ab-split FORCE_AB
