# SPDX-License-Identifier: BSD-3-Clause
"""occmap: Python bindings (ctypes) of the occmap C library (libocc.so).

    import numpy as np, occmap
    m = occmap.Map.load("geb079.bt")
    m.state_at(np.array([[1.0, 0.0, 0.5]], np.float32))   # -> array([1], dtype=uint8): FREE
"""
from ._convert import FREE, OCCUPIED, UNKNOWN
from ._lib import LIB_PATH
from .errors import (OccArgError, OccCorruptError, OccError, OccFormatError, OccIOError,
                     OccNoMemError, OccRangeError, OccScratchError, OccStateError, OccTimeError,
                     OccUnsupportedError)
from .map import Collision, Map, RayHit, Sectors

__all__ = ["Map", "Collision", "RayHit", "Sectors", "UNKNOWN", "FREE", "OCCUPIED", "LIB_PATH",
           "OccError", "OccArgError", "OccRangeError", "OccNoMemError", "OccFormatError",
           "OccIOError", "OccStateError", "OccUnsupportedError", "OccCorruptError",
           "OccScratchError", "OccTimeError"]
__version__ = "0.1.0"
