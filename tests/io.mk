# SPDX-License-Identifier: BSD-3-Clause
# tests/io.mk - the files issue: OctoMap .bt/.ot and snapshot tests, fuzzing, float build.
APT_PKGS += libclang-rt-14-dev

# The OctoMap file tests, split by topic: round trips (test_io_octomap.c) and refused input
# (test_io_corrupt.c). Both are built again below (optimized; float values) and run as steps.
IO_OCTOMAP_TESTS := test_io_octomap test_io_corrupt

# The shared maps (4.6 M nodes) are too slow under ASan: the same test files, optimized, run
# them as a step (OCC_IO_FULL=1 enables test_shared_maps).
IO_FULL_BINS := $(IO_OCTOMAP_TESTS:%=$(BUILD)/io/%_full)
$(BUILD)/io/%_full: $(BUILD)/relhost/tests/%.o $(BUILD)/relhost/tests/support/iotest.o \
                    $(BUILD)/relhost/tests/support/oracle_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(HOST_LIBS)
io-octomap-full: $(IO_FULL_BINS)
	@set -e; for b in $(IO_FULL_BINS); do echo "== $$b"; OCC_IO_FULL=1 $$b; done
TEST_STEPS += io-octomap-full
TEST_BUILD_EXTRA += $(IO_FULL_BINS)
.PHONY: io-octomap-full

# occmap convert against OctoMap's command-line tools (convert_octree, compare_octrees).
io-octomap-tools: $(BUILD)/occmap
	bash tests/io_tools.sh $(BUILD)
TEST_STEPS += io-octomap-tools
.PHONY: io-octomap-tools

# ---- fuzzing (libFuzzer, Debian's clang 14) ------------------------------------------------------
# One harness per reader; seeds are small crops of real maps (tests/fuzz/make_seeds.c) plus the
# regression inputs in tests/fuzz/regress/. `make fuzz` runs each for FUZZ_SECONDS; `make test`
# runs a short bounded smoke (IO_FUZZ_SMOKE seconds each). New crashes land in build/fuzz/.
FUZZ_CC := clang
FUZZ_SECONDS ?= 60
IO_FUZZ_SMOKE ?= 4
IO_FUZZ_FMTS := bt ot occ
IO_FUZZ_DIR := $(BUILD)/fuzz
IO_FUZZ_BINS := $(IO_FUZZ_FMTS:%=$(IO_FUZZ_DIR)/fuzz_%)
fuzz_fmt_bt := OCC_FORMAT_BT
fuzz_fmt_ot := OCC_FORMAT_OT
fuzz_fmt_occ := OCC_FORMAT_SNAPSHOT

IO_FUZZ_FLAGS := -std=c99 -O1 -g -fsanitize=fuzzer-no-link,address,undefined \
                 -fno-sanitize-recover=all -DOCC_TESTING=1 $(OCC_TEST_ASSERTS) $(INC)
IO_FUZZ_CORE := $(OCC_CORE_SRC:%.c=$(IO_FUZZ_DIR)/obj/%.o)
$(IO_FUZZ_DIR)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(IO_FUZZ_FLAGS) -MMD -MP -c $< -o $@
$(IO_FUZZ_DIR)/fuzz_%: tests/fuzz/fuzz_reader.c $(IO_FUZZ_CORE)
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(IO_FUZZ_FLAGS) -fsanitize=fuzzer -DFUZZ_FORMAT=$(fuzz_fmt_$*) \
	  tests/fuzz/fuzz_reader.c $(IO_FUZZ_CORE) -o $@

$(IO_FUZZ_DIR)/make_seeds: tests/fuzz/make_seeds.c port/posix/file_io.c $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CC) $(HOST_WARN) -Wno-error -O2 $(INC) $^ -o $@ -lm

IO_SEED_STAMP := $(IO_FUZZ_DIR)/seeds/.stamp
$(IO_SEED_STAMP): $(IO_FUZZ_DIR)/make_seeds $(wildcard tests/fuzz/regress/*)
	@rm -rf $(IO_FUZZ_DIR)/seeds && mkdir -p $(IO_FUZZ_DIR)/seeds/bt $(IO_FUZZ_DIR)/seeds/ot $(IO_FUZZ_DIR)/seeds/occ
	$(IO_FUZZ_DIR)/make_seeds $(IO_FUZZ_DIR)/seeds
	@for f in tests/fuzz/regress/*; do [ -f "$$f" ] || continue; \
	  case "$$f" in *.bt) cp "$$f" $(IO_FUZZ_DIR)/seeds/bt/;; *.ot) cp "$$f" $(IO_FUZZ_DIR)/seeds/ot/;; \
	  *.occ) cp "$$f" $(IO_FUZZ_DIR)/seeds/occ/;; esac; done
	@touch $@

# Run every harness for $(1) seconds on a scratch copy of the seeds (the seeds stay small).
define io_fuzz_run
	@set -e; for f in $(IO_FUZZ_FMTS); do \
	  rm -rf $(IO_FUZZ_DIR)/work_$$f && cp -r $(IO_FUZZ_DIR)/seeds/$$f $(IO_FUZZ_DIR)/work_$$f; \
	  echo "fuzz_$$f: $(1) s"; \
	  $(IO_FUZZ_DIR)/fuzz_$$f -max_total_time=$(1) -max_len=65536 -timeout=10 -rss_limit_mb=1024 \
	    -print_final_stats=1 -artifact_prefix=$(IO_FUZZ_DIR)/crash-$$f- \
	    $(IO_FUZZ_DIR)/work_$$f 2>&1 | grep -E "^(#[0-9]+ *DONE|stat::number_of_executed_units|stat::peak_rss|==.*ERROR|SUMMARY)" ; \
	  test $${PIPESTATUS[0]} -eq 0; \
	done
endef

io-fuzz-build: $(IO_FUZZ_BINS) $(IO_SEED_STAMP)
io-fuzz-smoke: io-fuzz-build
	$(call io_fuzz_run,$(IO_FUZZ_SMOKE))
fuzz-io: io-fuzz-build
	$(call io_fuzz_run,$(FUZZ_SECONDS))
TEST_BUILD_EXTRA += io-fuzz-build
TEST_STEPS += io-fuzz-smoke
FUZZ_STEPS += fuzz-io
.PHONY: io-fuzz-build io-fuzz-smoke fuzz-io

# ---- the float build (OCC_VALUE_FLOAT=1): .ot values round-trip bit-exactly ---------------------
IO_FLOAT_DIR := $(BUILD)/iofloat
IO_FLOAT_CFLAGS := $(HOST_WARN) -O2 -g $(INC) -DOCC_VALUE_FLOAT=1
$(IO_FLOAT_DIR)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(IO_FLOAT_CFLAGS) -MMD -MP -c $< -o $@
$(IO_FLOAT_DIR)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O2 -g $(INC) -DOCC_VALUE_FLOAT=1 -MMD -MP -c $< -o $@
IO_FLOAT_BINS := $(IO_OCTOMAP_TESTS:%=$(IO_FLOAT_DIR)/%_float)
$(IO_FLOAT_DIR)/%_float: $(OCC_CORE_SRC:%.c=$(IO_FLOAT_DIR)/%.o) $(IO_FLOAT_DIR)/tests/%.o \
                         $(IO_FLOAT_DIR)/tests/support/iotest.o $(IO_FLOAT_DIR)/tests/support/oracle_io.o
	$(CXX) -o $@ $^ $(HOST_LIBS)
io-float-exact: $(IO_FLOAT_BINS)
	@set -e; for b in $(IO_FLOAT_BINS); do echo "== $$b"; OCC_IO_FULL=1 OCC_IO_ONLY_OT=1 $$b; done
TEST_STEPS += io-float-exact
TEST_BUILD_EXTRA += $(IO_FLOAT_BINS)
.PHONY: io-float-exact
