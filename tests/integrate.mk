# SPDX-License-Identifier: BSD-3-Clause
# integrate.mk - point-cloud integration: test data and the OctoMap comparison steps.
# scan.dat (OctoMap's example laser scan) is decompressed once for tests, tools and the bench.
SCAN_DAT_BZ2 := /usr/share/doc/liboctomap-dev/examples/data/scan.dat.bz2
$(BUILD)/data/scan.dat: $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	bzcat $(SCAN_DAT_BZ2) > $@.tmp && mv $@.tmp $@
TEST_BUILD_EXTRA += $(BUILD)/data/scan.dat

# The command-line integrator on the real scan: JSON with the documented keys, the same voxel
# count as the library reports, and a usage error for a bad method.
integrate-cli: $(BUILD)/occmap $(BUILD)/data/scan.dat
	@out=$$(./$(BUILD)/occmap build --scan $(BUILD)/data/scan.dat --res 0.2 --method discrete --json) && \
	  echo "$$out" && \
	  for k in resolution_m memory_bytes points points_skipped voxels_updated integrate_ms; do \
	    echo "$$out" | grep -q "\"$$k\":" || { echo "missing key $$k"; exit 1; }; done && \
	  echo "$$out" | grep -q '"points": 88206' && \
	  ./$(BUILD)/occmap build --graph /usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph --res 0.1 --json | grep -q '"points": 10201' && \
	  { ./$(BUILD)/occmap build --scan $(BUILD)/data/scan.dat --method bogus >/dev/null 2>&1; test $$? -eq 2; }
TEST_STEPS += integrate-cli
.PHONY: integrate-cli

# The integration tests once more, linked against the release library (build/libocc.a: -O3,
# the projective lane loops vectorised, their AVX-512 or AVX2 clones where the CPU has them), so
# that the OctoMap and oracle comparisons cover the code `make bench` times, not only the ASan build's
# (-O1, scalar loops). The tests' own objects are the ASan build's (an uninstrumented library
# links with them).
REL_TWINS := test_integrate test_projective test_proj_range test_projective_fuzz
.SECONDEXPANSION:
$(REL_TWINS:%=$(BUILD)/asan/tests/bin/%_rel): $(BUILD)/asan/tests/bin/%_rel: \
    $(BUILD)/asanhost/tests/%.o $$(TEST_SUPPORT_OBJ) $$(TEST_PORT_OBJ) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) $(SAN) -o $@ $^ $(HOST_LIBS)
TEST_BINS_EXTRA += $(REL_TWINS:%=$(BUILD)/asan/tests/bin/%_rel)
