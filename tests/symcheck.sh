#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The core must not call the heap, stdio or process exit: nm -u of every core object. Nor the
# test build's assert hook: release and cross objects have OCC_ASSERT compiled out.
set -u
bad='^(malloc|calloc|realloc|free|printf|fprintf|sprintf|puts|putchar|abort|exit|_exit|fopen|mock_assert)$'
status=0; n=0
for dir in "$@"; do
  for o in $(find "$dir" -name '*.o' | sort); do
    n=$((n + 1))
    hits=$(nm -u "$o" 2>/dev/null | awk '{print $NF}' | grep -E "$bad")
    if [ -n "$hits" ]; then echo "symcheck: $o uses: $hits"; status=1; fi
  done
done
[ $n -gt 0 ] || { echo "symcheck: no objects found in $*"; exit 1; }
[ $status -eq 0 ] && echo "symcheck: $n core objects, none uses malloc/calloc/realloc/free/printf/puts/abort/exit/mock_assert"
exit $status
