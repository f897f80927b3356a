"""How invalid WebGL calls are reported: like a browser console (a warning), or raised (strict)."""


class GLWarning(UserWarning):
    """An invalid WebGL call: the error is recorded for getError() and nothing changed."""

    def __init__(self, code, call, reason):
        from . import _core
        self.code, self.call, self.reason = code, call, reason
        super().__init__(f"WebGL: {_core.error_name(code)}: {call}: {reason}")


class GLError(Exception):
    """Raised instead of GLWarning by a Context(strict=True)."""

    def __init__(self, code, call, reason):
        from . import _core
        self.code, self.call, self.reason = code, call, reason
        super().__init__(f"WebGL: {_core.error_name(code)}: {call}: {reason}")


class Float64Warning(UserWarning):
    """A float64 NumPy array met a WebGL call that reads 32-bit floats (bufferData,
    bufferSubData, texImage2D, texSubImage2D). WebGL takes the array's bytes as they are, so the
    data is almost surely meant as float32: write ``np.asarray(data, np.float32)``. Shown once
    per call site; a Context(strict=True) raises TypeError instead."""
