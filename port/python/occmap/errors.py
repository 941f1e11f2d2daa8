# SPDX-License-Identifier: BSD-3-Clause
"""C error codes (occ_err_t, occ_core.h) as Python exceptions: one OccError subclass per code,
each carrying the C name (.name, e.g. "OCC_ERR_NOMEM"), the code (.code) and occ_err_str()."""

CODES = {
    -1: "OCC_ERR_ARG", -2: "OCC_ERR_RANGE", -3: "OCC_ERR_NOMEM", -4: "OCC_ERR_FORMAT",
    -5: "OCC_ERR_IO", -6: "OCC_ERR_STATE", -7: "OCC_ERR_UNSUPPORTED", -8: "OCC_ERR_CORRUPT",
    -9: "OCC_ERR_SCRATCH", -10: "OCC_ERR_TIME",
}


class OccError(Exception):
    """A C call returned an error. .name is the C enumerator, .code its value, .text the C
    library's own text (occ_err_str), .detail what the binding adds (which call, byte offset)."""
    name = "OCC_ERR_UNKNOWN"
    code = 0

    def __init__(self, text="", detail=""):
        self.text = text
        self.detail = detail
        msg = f"{self.name}: {text}" + (f" ({detail})" if detail else "")
        super().__init__(msg)


class OccArgError(OccError, ValueError):
    name, code = "OCC_ERR_ARG", -1


class OccRangeError(OccError, ValueError):
    name, code = "OCC_ERR_RANGE", -2


class OccNoMemError(OccError, MemoryError):
    name, code = "OCC_ERR_NOMEM", -3


class OccFormatError(OccError):
    name, code = "OCC_ERR_FORMAT", -4


class OccIOError(OccError, OSError):
    name, code = "OCC_ERR_IO", -5


class OccStateError(OccError):
    name, code = "OCC_ERR_STATE", -6


class OccUnsupportedError(OccError):
    name, code = "OCC_ERR_UNSUPPORTED", -7


class OccCorruptError(OccError):
    name, code = "OCC_ERR_CORRUPT", -8


class OccScratchError(OccError):
    name, code = "OCC_ERR_SCRATCH", -9


class OccTimeError(OccError):
    name, code = "OCC_ERR_TIME", -10


BY_CODE = {cls.code: cls for cls in (
    OccArgError, OccRangeError, OccNoMemError, OccFormatError, OccIOError, OccStateError,
    OccUnsupportedError, OccCorruptError, OccScratchError, OccTimeError)}
assert {c: k.name for c, k in BY_CODE.items()} == CODES


def error_for(code, text, detail=""):
    """The exception for a C error code (an unknown code still raises: fail closed)."""
    cls = BY_CODE.get(code)
    if cls is None:
        err = OccError(text, detail)
        err.code = code
        return err
    return cls(text, detail)
