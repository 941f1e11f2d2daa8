# layout.mk - the dependency check (issue 17): every #include of src/<module>/*.c|h resolved and
# tested against the one allowed direction geom <- core <- {integrate, query, io, evict} <- front
# ends (public headers only); nothing in src includes port/ or tools/. It prints the module graph
# it found and proves itself on planted wrong-way includes in a scratch copy of the tree.
deps-check:
	@python3 tests/deps_check.py .
TEST_STEPS += deps-check
.PHONY: deps-check
