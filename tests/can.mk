# SPDX-License-Identifier: BSD-3-Clause
# can.mk - the DroneCAN front end's test steps (issue 8):
#   test-can-golden  pydronecan encodes thousands of field values; ours must equal byte for byte,
#                    and pydronecan must decode ours (tests/can/golden.py + golden_dump.c)
#   test-can-qemu    the SocketCAN port on a real kernel CAN bus: a stock Debian kernel under qemu
#                    with vcan0, candump capturing, pydronecan decoding (tests/can/qemu_socketcan.sh)
#   test-can-mcast   occmap can-feed on pydronecan's mcast: bus inside a network namespace with only
#                    loopback: fixed pose, then live MAVLink poses and NO_DATA (tests/can/mcast_peer.py)
# The CMocka unit tests are tests/test_dronecan.c and tests/test_dronecan_node.c (built by the top Makefile).
APT_PKGS += qemu-system-x86 busybox-static cpio can-utils

CAN_BUILD := $(BUILD)/can
CAN_HOST_CFLAGS = $(HOST_WARN) -O2 -g $(INC) $(EXTRA_CFLAGS)

$(CAN_BUILD)/golden_dump: tests/can/golden_dump.c $(BUILD)/libocc.a include/occmap/occ_dronecan.h
	@mkdir -p $(dir $@)
	$(CC) $(CAN_HOST_CFLAGS) -o $@ $< $(BUILD)/libocc.a -lm

# Static, so the guest's initramfs needs no libraries for it.
$(CAN_BUILD)/socketcan_guest: tests/can/socketcan_guest.c port/posix/socketcan.c \
                              port/posix/fd_wait.c $(BUILD)/libocc.a include/occmap/occ_dronecan.h \
                              include/occmap/host/occ_socketcan.h
	@mkdir -p $(dir $@)
	$(CC) $(CAN_HOST_CFLAGS) -static -o $@ tests/can/socketcan_guest.c port/posix/socketcan.c \
	  port/posix/fd_wait.c $(BUILD)/libocc.a -lm

$(CAN_BUILD)/make_wall_map: $(BUILD)/relhost/tests/can/make_wall_map.o \
                            $(PORT_SRC:%.c=$(BUILD)/relhost/%.o) $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CXX) -o $@ $^ $(HOST_LIBS)
$(CAN_BUILD)/wall.occ: $(CAN_BUILD)/make_wall_map
	$(CAN_BUILD)/make_wall_map $@

test-can-golden: $(CAN_BUILD)/golden_dump $(BUILD)/.deps-ok
	$(PY) tests/can/golden.py $(CAN_BUILD)/golden_dump 2000

test-can-qemu: $(CAN_BUILD)/socketcan_guest $(BUILD)/occmap $(CAN_BUILD)/wall.occ $(BUILD)/.deps-ok
	bash tests/can/qemu_socketcan.sh $(BUILD) $(CAN_BUILD)/socketcan_guest $(PY) $(BUILD)/occmap \
	  $(CAN_BUILD)/wall.occ

test-can-mcast: $(BUILD)/occmap $(CAN_BUILD)/wall.occ $(BUILD)/.deps-ok
	bash tests/can/mcast_netns.sh $(BUILD)/occmap $(CAN_BUILD)/wall.occ $(PY)

TEST_STEPS += test-can-golden test-can-qemu test-can-mcast
.PHONY: test-can-golden test-can-qemu test-can-mcast
