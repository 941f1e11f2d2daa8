# query.mk - `make bench` step: collision checks, ray casts, line of sight and information gain
# against OctoMap in the same run (bench/query.cpp) on geb079.bt and ../shared/data/maps/*.
# Writes build/bench/query.json.
BENCH_QUERY_MAPS := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt \
  $(wildcard ../shared/data/maps/*.bt ../shared/data/maps/*.ot)
$(BUILD)/bench/query: bench/query.cpp $(BUILD)/relhost/port/posix/file_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++14 -O2 -g -Wall -Wextra -Werror $(INC) -o $@ $^ -loctomap -loctomath -lm
bench-query: $(BUILD)/bench/query
	./$(BUILD)/bench/query --json $(BUILD)/bench/query.json $(BENCH_QUERY_MAPS)
BENCH_STEPS += bench-query
.PHONY: bench-query
