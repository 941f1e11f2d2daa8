# SPDX-License-Identifier: BSD-3-Clause
# bench/io.mk - file load/save times for geb079.bt against OctoMap's readBinary/writeBinary in
# the same run (median of 7), plus .ot/.occ times and bytes per file. OctoMap's progress lines
# on stderr are filtered out.
IO_BENCH_BIN := $(BUILD)/bench/bench_io
$(IO_BENCH_BIN): $(BUILD)/relhost/bench/bench_io.o $(BUILD)/relhost/port/posix/file_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -O2 -o $@ $^ $(HOST_LIBS)
bench-io: $(IO_BENCH_BIN)
	@$(IO_BENCH_BIN) /usr/share/doc/liboctomap-dev/examples/data/geb079.bt 7 2>&1 \
	  | grep -vE "^(Reading|Writing|Done)"; exit $${PIPESTATUS[0]}
BENCH_STEPS += bench-io
.PHONY: bench-io
