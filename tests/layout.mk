# layout.mk - the dependency checks (issue 17).
# deps-check: every #include of src/<module>/*.c|h resolved and tested against the one allowed
# direction geom <- core <- {integrate, query, io, evict} <- front ends (public headers only);
# nothing in src includes port/ or tools/. It prints the module graph it found and proves itself
# on planted wrong-way includes in a scratch copy of the tree.
# deps-calls: the same direction for the calls the compiled objects of libocc.a make (nm), so a
# hand-written prototype cannot go around the include check; proves itself on planted calls.
deps-check:
	@python3 tests/deps_check.py .
deps-calls: $(BUILD)/libocc.a
	@python3 tests/deps_calls.py $(BUILD)/rel
TEST_STEPS += deps-check deps-calls
.PHONY: deps-check deps-calls
