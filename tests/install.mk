# SPDX-License-Identifier: BSD-3-Clause
# install.mk - `make install` into a staging prefix and a consumer built against it with
# pkg-config and with CMake (tests/install_consumer/run.sh). Seconds.
APT_PKGS += pkg-config cmake
TEST_STEPS += test-install
test-install: $(BUILD)/libocc.a $(BUILD)/libocc.so $(BUILD)/libocc_posix.a $(BUILD)/occmap view-assets
	@bash tests/install_consumer/run.sh $(BUILD)
.PHONY: test-install
