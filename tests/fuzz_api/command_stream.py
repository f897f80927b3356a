"""A WebGL command-stream fuzzer for softgl (docs/reliability.md, "API fuzzing").

`CommandFuzzer(seed).step()` makes one random WebGL call on one of two contexts with random --
mostly plausible, often invalid -- arguments: enums from the whole WebGL table and out of it,
integers at the 32/64-bit edges, NaN/Inf floats, objects of this context, of the other context,
deleted objects and None, typed arrays of every kind, huge sizes and counts. Between calls it
creates and deletes objects, including objects that are bound or in use, switches the error
listener between warning and raising (strict), and installs a GLWarning handler that calls back
into the context while the failing call is still on the stack (re-entrancy).

After every call it checks the contract of docs/architecture.md, "Layers": the process is alive; the
call either succeeded, or recorded exactly the error it reported (GLWarning / GLError) and changed
nothing observable (every getParameter value, the vertex attribute state, the bound buffers' sizes,
the program's uniforms and the drawing buffer's pixels). Any other exception is a failure.

The same class drives the bounded hypothesis test (test_command_stream.py) and the long runs
(tools/fuzz_api.py).
"""
from __future__ import annotations

import math
import warnings

import numpy as np

import softgl
from softgl import _core

# ----------------------------------------------------------------------------- material

VS_SOURCES = [
    "attribute vec4 aPos; void main() { gl_Position = aPos; gl_PointSize = 2.0; }",
    """attribute vec4 aPos; attribute vec4 aColor; uniform mat4 uM; uniform float uS[3];
varying vec4 vC; void main() { gl_Position = uM * aPos * uS[1]; vC = aColor; gl_PointSize = 3.0; }""",
    "void main() { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); gl_PointSize = 4.0; }",
    """#version 300 es
in vec4 aPos; in ivec2 aI; uniform uvec2 uU; flat out int vI;
void main() { gl_Position = aPos + vec4(float(uU.x), 0.0, 0.0, 0.0); vI = aI.x; gl_PointSize = 1.0; }""",
    "attribute vec4 aPos; void main() { gl_Position = aPos",          # does not compile
    "",
]
FS_SOURCES = [
    "precision mediump float; uniform vec4 uColor; void main() { gl_FragColor = uColor; }",
    "precision mediump float; varying vec4 vC; void main() { gl_FragColor = vC; }",
    "precision mediump float; uniform int uI; void main() { if (uI > 2) discard; gl_FragColor = vec4(1.0); }",
    """#version 300 es
precision highp float; precision highp int; flat in int vI; out vec4 o; uniform ivec3 uV;
void main() { o = vec4(float(vI + uV.y), 0.5, 0.25, 1.0); }""",
    "void main() { gl_FragColor = vec4(1.0); }",                     # no precision: error
]
NAMES = ["aPos", "aColor", "aI", "uM", "uS", "uS[0]", "uS[2]", "uS[3]", "uColor", "uI", "uU", "uV",
         "gl_Position", "webgl_x", "", "a" * 300, "uColor\x00x"]

PARAMETER_NAMES = [  # state compared before and after a failing call
    "ACTIVE_TEXTURE", "ARRAY_BUFFER_BINDING", "BLEND", "BLEND_COLOR", "BLEND_DST_ALPHA",
    "BLEND_DST_RGB", "BLEND_EQUATION_ALPHA", "BLEND_EQUATION_RGB", "BLEND_SRC_ALPHA", "BLEND_SRC_RGB",
    "COLOR_CLEAR_VALUE", "COLOR_WRITEMASK", "CULL_FACE", "CULL_FACE_MODE", "CURRENT_PROGRAM",
    "DEPTH_CLEAR_VALUE", "DEPTH_FUNC", "DEPTH_RANGE", "DEPTH_TEST", "DEPTH_WRITEMASK", "DITHER",
    "ELEMENT_ARRAY_BUFFER_BINDING", "FRONT_FACE", "GENERATE_MIPMAP_HINT", "LINE_WIDTH",
    "PACK_ALIGNMENT", "POLYGON_OFFSET_FACTOR", "POLYGON_OFFSET_FILL", "POLYGON_OFFSET_UNITS",
    "SAMPLE_ALPHA_TO_COVERAGE", "SAMPLE_COVERAGE", "SAMPLE_COVERAGE_INVERT", "SAMPLE_COVERAGE_VALUE",
    "SCISSOR_BOX", "SCISSOR_TEST", "STENCIL_BACK_FAIL", "STENCIL_BACK_FUNC",
    "STENCIL_BACK_PASS_DEPTH_FAIL", "STENCIL_BACK_PASS_DEPTH_PASS", "STENCIL_BACK_REF",
    "STENCIL_BACK_VALUE_MASK", "STENCIL_BACK_WRITEMASK", "STENCIL_CLEAR_VALUE", "STENCIL_FAIL",
    "STENCIL_FUNC", "STENCIL_PASS_DEPTH_FAIL", "STENCIL_PASS_DEPTH_PASS", "STENCIL_REF",
    "STENCIL_TEST", "STENCIL_VALUE_MASK", "STENCIL_WRITEMASK", "UNPACK_ALIGNMENT",
    "UNPACK_FLIP_Y_WEBGL", "UNPACK_PREMULTIPLY_ALPHA_WEBGL", "UNPACK_COLORSPACE_CONVERSION_WEBGL",
    "VIEWPORT", "VERTEX_ARRAY_BINDING", "COPY_READ_BUFFER_BINDING", "COPY_WRITE_BUFFER_BINDING",
    "PIXEL_PACK_BUFFER_BINDING", "PIXEL_UNPACK_BUFFER_BINDING", "UNIFORM_BUFFER_BINDING",
    "PACK_ROW_LENGTH", "PACK_SKIP_PIXELS", "PACK_SKIP_ROWS", "UNPACK_ROW_LENGTH",
    "UNPACK_IMAGE_HEIGHT", "UNPACK_SKIP_PIXELS", "UNPACK_SKIP_ROWS", "UNPACK_SKIP_IMAGES",
    "FRAGMENT_SHADER_DERIVATIVE_HINT", "RASTERIZER_DISCARD",
]
ATTRIB_NAMES = ["VERTEX_ATTRIB_ARRAY_ENABLED", "VERTEX_ATTRIB_ARRAY_SIZE", "VERTEX_ATTRIB_ARRAY_TYPE",
                "VERTEX_ATTRIB_ARRAY_STRIDE", "VERTEX_ATTRIB_ARRAY_NORMALIZED",
                "VERTEX_ATTRIB_ARRAY_BUFFER_BINDING", "CURRENT_VERTEX_ATTRIB"]
ATTRIB_NAMES_2 = ["VERTEX_ATTRIB_ARRAY_DIVISOR", "VERTEX_ATTRIB_ARRAY_INTEGER"]

ALL_ENUMS = sorted({value for _, value, _ in _core.ENUMS})
SOFTGL_ENUMS = [0x0B60, 0x0B62, 0x0B63, 0x0B64, 0x0B65, 0x0B66, 0x2601, 0x0800, 0x0801, 0x8450,
                0x8452, 0x1D000, 0x1D001, 0x0B10, 0x0B20, 0x0B41, 0x0C51, 0x0C52, 0x0C53]
INTS = [0, 1, 2, 3, 4, 5, 8, 15, 16, 17, 255, 256, 1024, 16384, 16385, -1, -2, 2**31 - 1, -2**31,
        2**32 - 1, 2**32, 2**40]
INT64S = [0, 1, 2, 3, 4, 8, 12, 16, 64, 1000, -1, -4, 2**31 - 1, 2**31, 2**32, 2**33 + 1, 2**34 + 1,
          2**62, 2**63 - 1, -2**63]
FLOATS = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-45, 1e38, 3.4028235e38, -3.4e38, math.nan, math.inf,
          -math.inf, 1e300]
DTYPES = [np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.float32, np.float64]
MODES = [0, 1, 2, 3, 4, 5, 6]
# Draw counts above this are only sent when an enabled, used attribute array bounds them: an
# unbounded huge draw is real work (known issue, see docs/reliability.md), not a validation test.
MAX_UNBOUNDED_VERTICES = 4096


class Violation(AssertionError):
    """The command-stream contract was broken; the message holds the call log."""


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return False
        return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, (list, tuple)):
        return isinstance(b, type(a)) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (int, bool, str, type(None))):
        return type(a) is type(b) and a == b
    return a is b   # WebGL objects: the very same handle


class Side:
    """One context and the objects made with it."""

    def __init__(self, version: int, antialias: bool, strict: bool):
        self.gl = softgl.Context(4, 4, version=version, antialias=antialias, stencil=True,
                                 strict=strict, preserveDrawingBuffer=True)
        self.strict = strict
        self.objects = {"buffer": [], "vao": [], "program": [], "shader": [], "location": []}
        self.deleted = {k: [] for k in self.objects}
        gl = self.gl
        self.pnames = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            for name in PARAMETER_NAMES:
                pname = getattr(gl, name, None)
                if pname is None:
                    continue
                try:
                    gl.getParameter(pname)
                except softgl.GLError:
                    continue
                if gl.getError() == gl.NO_ERROR:
                    self.pnames.append(pname)
            self.attrib_pnames = [getattr(gl, n) for n in ATTRIB_NAMES + (ATTRIB_NAMES_2 if version == 2 else [])]
            gl.getError()


class CommandFuzzer:
    def __init__(self, seed: int, version: int | None = None):
        self.rng = np.random.default_rng(seed)
        self.version = version or int(self.rng.integers(1, 3))
        strict = bool(self.rng.random() < 0.3)
        self.sides = [Side(self.version, bool(self.rng.random() < 0.3), strict),
                      Side(self.version, False, not strict)]
        self.log: list[str] = []
        self.calls = 0
        self.errors = 0
        self.reentrant = None        # None, "readonly" or "mutating"
        self.reentry_depth = 0
        self.reentered = 0
        self.reported: list[int] = []
        self.exceptions_allowed = 0
        for side in self.sides:
            side.gl._set_error_listener(self._listener(side))
            self._seed_objects(side)

    # -- error listener: records what each call reports, optionally calls back in ----------------

    def _listener(self, side: Side):
        def listener(code, call, reason):
            self.reported.append(code)
            if self.reentrant and self.reentry_depth == 0:
                self.reentry_depth += 1
                try:
                    self._reenter(side)
                finally:
                    self.reentry_depth -= 1
            if side.strict:
                raise softgl.GLError(code, call, reason)
            warnings.warn(softgl.GLWarning(code, call, reason), stacklevel=2)
        return listener

    def _reenter(self, side: Side):
        """Called while the failing call is still on the stack (a GLWarning handler that uses
        the context). Read-only calls must leave the failing call's contract intact; mutating
        ones (delete the program in use, redefine the bound buffer, draw) must not crash."""
        gl, rng = side.gl, self.rng
        self.reentered += 1
        before = list(self.reported)
        try:
            gl.getParameter(gl.VIEWPORT)
            gl.isEnabled(gl.BLEND)
            gl.readPixels(0, 0, 2, 2, gl.RGBA, gl.UNSIGNED_BYTE)
            gl.enable(0xDEAD)     # a nested error: reported, but not re-entered again
            if self.reentrant == "mutating":
                choice = int(rng.integers(0, 5))
                if choice == 0 and side.objects["program"]:
                    gl.deleteProgram(side.objects["program"][int(rng.integers(len(side.objects["program"])))])
                elif choice == 1:
                    gl.bufferData(gl.ARRAY_BUFFER, int(rng.integers(0, 64)), gl.STATIC_DRAW)
                elif choice == 2:
                    gl.drawArrays(gl.TRIANGLES, 0, 3)
                elif choice == 3:
                    gl.bindVertexArray(None) if self.version == 2 else gl.useProgram(None)
                else:
                    gl.getError()
        except softgl.GLError:
            pass
        # What the nested calls reported is theirs, not the outer call's.
        del self.reported[len(before):]

    # -- objects ---------------------------------------------------------------------------------

    def _seed_objects(self, side: Side):
        gl = side.gl
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            for _ in range(2):
                side.objects["buffer"].append(gl.createBuffer())
            if self.version == 2:
                side.objects["vao"].append(gl.createVertexArray())
            for vs, fs in ((0, 0), (1, 1), (2, 2)):
                try:
                    prog = softgl.program(gl, VS_SOURCES[vs], FS_SOURCES[fs], {"aPos": 0})
                except softgl.GLError:
                    continue
                side.objects["program"].append(prog)
                self._collect_locations(side, prog)
            gl.getError()
        self.reported.clear()

    def _collect_locations(self, side: Side, prog):
        for name in ("uM", "uS", "uS[2]", "uColor", "uI", "uU", "uV"):
            try:
                loc = side.gl.getUniformLocation(prog, name)
            except softgl.GLError:
                continue
            if loc is not None:
                side.objects["location"].append(loc)

    def pick_object(self, side: Side, kind: str):
        r = self.rng.random()
        other = self.sides[1] if side is self.sides[0] else self.sides[0]
        if r < 0.05:
            return None
        if r < 0.10 and side.deleted[kind]:
            return side.deleted[kind][int(self.rng.integers(len(side.deleted[kind])))]
        if r < 0.15 and other.objects[kind]:
            return other.objects[kind][int(self.rng.integers(len(other.objects[kind])))]
        pool = side.objects[kind]
        if not pool:
            return None
        return pool[int(self.rng.integers(len(pool)))]

    # -- argument generators -----------------------------------------------------------------------

    def enum(self, valid=()):
        r = self.rng.random()
        if valid and r < 0.85:
            return int(valid[int(self.rng.integers(len(valid)))])
        if r < 0.95:
            return int(ALL_ENUMS[int(self.rng.integers(len(ALL_ENUMS)))])
        if r < 0.97:
            return int(SOFTGL_ENUMS[int(self.rng.integers(len(SOFTGL_ENUMS)))])
        return int([0, 1, -1, 0xFFFFFFFF, 2**31, 0xDEAD, 2**32 + 0x0BE2][int(self.rng.integers(7))])

    def int_(self, lo=0, hi=8):
        if self.rng.random() < 0.85:
            return int(self.rng.integers(lo, hi + 1))
        return int(INTS[int(self.rng.integers(len(INTS)))])

    def int64(self, lo=0, hi=64):
        if self.rng.random() < 0.85:
            return int(self.rng.integers(lo, hi + 1))
        return int(INT64S[int(self.rng.integers(len(INT64S)))])

    def float_(self):
        if self.rng.random() < 0.75:
            return float(self.rng.uniform(-1.5, 1.5))
        return float(FLOATS[int(self.rng.integers(len(FLOATS)))])

    def bool_(self):
        return bool(self.rng.random() < 0.5)

    def array(self, max_len=48, dtype=None):
        dtype = dtype or DTYPES[int(self.rng.integers(len(DTYPES)))]
        n = int(self.rng.integers(0, max_len + 1))
        if np.dtype(dtype).kind == "f":
            a = self.rng.uniform(-2, 2, n).astype(dtype)
            if n and self.rng.random() < 0.3:
                a[int(self.rng.integers(n))] = [np.nan, np.inf, -np.inf][int(self.rng.integers(3))]
            return self.layout(a)
        info = np.iinfo(dtype)
        return self.layout(self.rng.integers(max(info.min, -4), min(info.max, 8), n, endpoint=True).astype(dtype))

    def layout(self, a):
        """Mostly `a`; else the same values in another NumPy layout (big-endian, strided, Fortran
        order, misaligned) or something the array intake refuses (read-only, object, a list):
        docs/reliability.md, "Array intake"."""
        if a.size < 2 or self.rng.random() < 0.8:
            return a
        pick = int(self.rng.integers(7))
        if pick == 0:
            return a.astype(a.dtype.newbyteorder(">"))
        if pick == 1:
            strided = np.zeros(2 * a.size, a.dtype)
            strided[::2] = a
            return strided[::2]
        if pick == 2:
            return np.asfortranarray(a[: a.size // 2 * 2].reshape(2, -1))
        if pick == 3:
            return np.frombuffer(bytearray(b"\0" + a.tobytes()), a.dtype, offset=1)
        if pick == 4:
            read_only = a.copy()
            read_only.flags.writeable = False
            return read_only
        return a.astype(object) if pick == 5 else a.tolist()

    def floats(self, max_len=20):
        return [self.float_() for _ in range(int(self.rng.integers(0, max_len + 1)))]

    def vertex_data(self):
        """Mostly plausible vertex positions in [-1.2, 1.2]^2 with w = 1, as float32."""
        n = int(self.rng.integers(0, 40))
        p = self.rng.uniform(-1.2, 1.2, (n, 4)).astype(np.float32)
        p[:, 3] = 1
        if n and self.rng.random() < 0.2:
            p.flat[int(self.rng.integers(p.size))] = [np.nan, np.inf, -np.inf, 0.0][int(self.rng.integers(4))]
        return p

    # -- the calls ----------------------------------------------------------------------------------

    def make_call(self, side: Side):
        """(method name, args, kwargs) for one random call on `side`."""
        gl, R = side.gl, self.rng
        E, I, I64, F, B = self.enum, self.int_, self.int64, self.float_, self.bool_
        obj = lambda kind: self.pick_object(side, kind)
        v2 = self.version == 2
        targets = [gl.ARRAY_BUFFER, gl.ELEMENT_ARRAY_BUFFER] + ([0x8F36, 0x8F37, 0x88EB, 0x88EC, 0x8A11] if v2 else [])
        usages = [gl.STATIC_DRAW, gl.DYNAMIC_DRAW, gl.STREAM_DRAW, 0x88E9, 0x88E6]
        factors = [0, 1, 0x300, 0x301, 0x302, 0x303, 0x304, 0x305, 0x306, 0x307, 0x308, 0x8001,
                   0x8002, 0x8003, 0x8004]
        caps = [gl.BLEND, gl.CULL_FACE, gl.DEPTH_TEST, gl.DITHER, gl.POLYGON_OFFSET_FILL,
                gl.SAMPLE_ALPHA_TO_COVERAGE, gl.SAMPLE_COVERAGE, gl.SCISSOR_TEST, gl.STENCIL_TEST]
        funcs = list(range(0x200, 0x208))
        ops = [0, 0x1E00, 0x1E01, 0x1E02, 0x1E03, 0x150A, 0x8507, 0x8508]
        faces = [0x404, 0x405, 0x408]
        types = [0x1400, 0x1401, 0x1402, 0x1403, 0x1404, 0x1405, 0x1406, 0x140B, 0x8368, 0x8D9F]
        idx_types = [0x1401, 0x1403, 0x1405]
        table = [
            ("enable", lambda: (E(caps),)), ("disable", lambda: (E(caps),)),
            ("isEnabled", lambda: (E(caps),)),
            ("blendFunc", lambda: (E(factors), E(factors))),
            ("blendFuncSeparate", lambda: (E(factors), E(factors), E(factors), E(factors))),
            ("blendEquation", lambda: (E([0x8006, 0x800A, 0x800B, 0x8007, 0x8008]),)),
            ("blendEquationSeparate", lambda: (E([0x8006, 0x800A, 0x800B, 0x8007, 0x8008]),) * 2),
            ("blendColor", lambda: (F(), F(), F(), F())),
            ("depthFunc", lambda: (E(funcs),)), ("depthMask", lambda: (B(),)),
            ("depthRange", lambda: (F(), F())),
            ("clearColor", lambda: (F(), F(), F(), F())), ("clearDepth", lambda: (F(),)),
            ("clearStencil", lambda: (I(-2, 300),)),
            ("colorMask", lambda: (B(), B(), B(), B())),
            ("stencilFunc", lambda: (E(funcs), I(-2, 300), I(0, 2**32 - 1))),
            ("stencilFuncSeparate", lambda: (E(faces), E(funcs), I(-2, 300), I(0, 255))),
            ("stencilOp", lambda: (E(ops), E(ops), E(ops))),
            ("stencilOpSeparate", lambda: (E(faces), E(ops), E(ops), E(ops))),
            ("stencilMask", lambda: (I(0, 255),)), ("stencilMaskSeparate", lambda: (E(faces), I(0, 255))),
            ("cullFace", lambda: (E(faces),)), ("frontFace", lambda: (E([0x900, 0x901]),)),
            ("lineWidth", lambda: (F(),)), ("polygonOffset", lambda: (F(), F())),
            ("sampleCoverage", lambda: (F(), B())),
            ("scissor", lambda: (I(-4, 8), I(-4, 8), I(-1, 8), I(-1, 8))),
            ("viewport", lambda: (I(-4, 8), I(-4, 8), I(-1, 8), I(-1, 8))),
            ("hint", lambda: (E([0x8192, 0x8B8B]), E([0x1100, 0x1101, 0x1102]))),
            ("pixelStorei", lambda: (E([0x0D05, 0x0CF5, 0x9240, 0x9241, 0x9243, 0x0D02, 0x0D03, 0x0D04]), I(-1, 9))),
            ("activeTexture", lambda: (E([0x84C0 + k for k in range(40)]),)),
            ("getParameter", lambda: (E(side.pnames),)),
            ("clear", lambda: (int(R.choice([0x4000, 0x100, 0x400, 0x4500, 0, 1, 0xFFFFFFFF, 0x4501])),)),
            ("readPixels", lambda: (I(-3, 6), I(-3, 6), I(-1, 6), I(-1, 6), E([gl.RGBA, 0x1907, 0x8D99]),
                                    E([gl.UNSIGNED_BYTE, gl.FLOAT, 0x1405, 0x1404]))),
            ("createBuffer", lambda: ()), ("createProgram", lambda: ()),
            ("createShader", lambda: (E([gl.VERTEX_SHADER, gl.FRAGMENT_SHADER]),)),
            ("bindBuffer", lambda: (E(targets), obj("buffer"))),
            ("deleteBuffer", lambda: (obj("buffer"),)), ("isBuffer", lambda: (obj("buffer"),)),
            ("bufferData", lambda: (E(targets), self.vertex_data() if R.random() < 0.5 else self.array(),
                                    E(usages))),
            ("bufferData", lambda: (E(targets), I64(0, 256), E(usages))),
            ("bufferData", lambda: (E(targets), self.array(), E(usages), I64(0, 8), I64(0, 8))),
            ("bufferSubData", lambda: (E(targets), I64(0, 64), self.array(16))),
            ("getBufferParameter", lambda: (E(targets), E([0x8764, 0x8765]))),
            ("vertexAttribPointer", lambda: (I(0, 17), I(0, 5), E(types), B(), I(0, 64), I64(0, 32))),
            ("enableVertexAttribArray", lambda: (I(0, 17),)),
            ("disableVertexAttribArray", lambda: (I(0, 17),)),
            ("vertexAttrib4f", lambda: (I(0, 17), F(), F(), F(), F())),
            ("vertexAttrib1fv", lambda: (I(0, 17), self.floats(3))),
            ("vertexAttrib4fv", lambda: (I(0, 17), self.floats(6))),
            ("getVertexAttrib", lambda: (I(0, 17), E(side.attrib_pnames))),
            ("getVertexAttribOffset", lambda: (I(0, 17), E([0x8645]))),
            ("shaderSource", lambda: (obj("shader"), (VS_SOURCES + FS_SOURCES)[int(R.integers(len(VS_SOURCES) + len(FS_SOURCES)))])),
            ("compileShader", lambda: (obj("shader"),)),
            ("getShaderParameter", lambda: (obj("shader"), E([0x8B4F, 0x8B80, 0x8B81]))),
            ("getShaderInfoLog", lambda: (obj("shader"),)), ("getShaderSource", lambda: (obj("shader"),)),
            ("deleteShader", lambda: (obj("shader"),)), ("isShader", lambda: (obj("shader"),)),
            ("attachShader", lambda: (obj("program"), obj("shader"))),
            ("detachShader", lambda: (obj("program"), obj("shader"))),
            ("getAttachedShaders", lambda: (obj("program"),)),
            ("bindAttribLocation", lambda: (obj("program"), I(0, 17), NAMES[int(R.integers(len(NAMES)))])),
            ("linkProgram", lambda: (obj("program"),)), ("validateProgram", lambda: (obj("program"),)),
            ("useProgram", lambda: (obj("program"),)), ("deleteProgram", lambda: (obj("program"),)),
            ("isProgram", lambda: (obj("program"),)),
            ("getProgramParameter", lambda: (obj("program"), E([0x8B80, 0x8B82, 0x8B83, 0x8B85, 0x8B86, 0x8B89]))),
            ("getProgramInfoLog", lambda: (obj("program"),)),
            ("getAttribLocation", lambda: (obj("program"), NAMES[int(R.integers(len(NAMES)))])),
            ("getUniformLocation", lambda: (obj("program"), NAMES[int(R.integers(len(NAMES)))])),
            ("getActiveAttrib", lambda: (obj("program"), I(0, 4))),
            ("getActiveUniform", lambda: (obj("program"), I(0, 6))),
            ("getUniform", lambda: (obj("program"), obj("location"))),
            ("uniform1f", lambda: (obj("location"), F())), ("uniform1i", lambda: (obj("location"), I(-2, 40))),
            ("uniform4f", lambda: (obj("location"), F(), F(), F(), F())),
            ("uniform3i", lambda: (obj("location"), I(), I(), I())),
            ("uniform1fv", lambda: (obj("location"), self.floats(5))),
            ("uniform4fv", lambda: (obj("location"), self.array(12, np.float32))),
            ("uniform1iv", lambda: (obj("location"), self.array(4, np.int32))),
            ("uniformMatrix4fv", lambda: (obj("location"), B(), self.array(40, np.float32))),
            ("drawArrays", lambda: (E(MODES), I(-1, 12), I(-1, 40))),
            ("drawElements", lambda: (E(MODES), I(-1, 40), E(idx_types), I64(0, 16))),
            ("getError", lambda: ()), ("isContextLost", lambda: ()), ("flush", lambda: ()),
            ("getExtension", lambda: (["SOFTGL_fog", "SOFTGL_smooth", "EXT_blend_minmax",
                                       "OES_vertex_array_object", "ANGLE_instanced_arrays",
                                       "OES_element_index_uint", "WEBGL_nope"][int(R.integers(7))],)),
        ]
        if v2:
            table += [
                ("createVertexArray", lambda: ()), ("bindVertexArray", lambda: (obj("vao"),)),
                ("deleteVertexArray", lambda: (obj("vao"),)), ("isVertexArray", lambda: (obj("vao"),)),
                ("copyBufferSubData", lambda: (E(targets), E(targets), I64(0, 32), I64(0, 32), I64(0, 32))),
                ("getBufferSubData", lambda: (E(targets), I64(0, 32), self.array(16), I64(0, 4), I64(0, 4))),
                ("vertexAttribIPointer", lambda: (I(0, 17), I(0, 5), E(types), I(0, 64), I64(0, 32))),
                ("vertexAttribI4i", lambda: (I(0, 17), I(), I(), I(), I())),
                ("vertexAttribDivisor", lambda: (I(0, 17), I(0, 3))),
                ("uniform2ui", lambda: (obj("location"), I(), I())),
                ("uniform4uiv", lambda: (obj("location"), self.array(8, np.uint32))),
                ("uniformMatrix2x3fv", lambda: (obj("location"), B(), self.array(12, np.float32), I64(0, 3), I64(0, 6))),
                ("drawArraysInstanced", lambda: (E(MODES), I(-1, 8), I(-1, 20), I(-1, 4))),
                ("drawElementsInstanced", lambda: (E(MODES), I(-1, 20), E(idx_types), I64(0, 8), I(-1, 4))),
                ("drawRangeElements", lambda: (E(MODES), I(0, 8), I(0, 8), I(-1, 20), E(idx_types), I64(0, 8))),
            ]
        name, make = table[int(R.integers(len(table)))]
        return name, make()

    # -- the contract -------------------------------------------------------------------------------

    def snapshot(self, side: Side):
        # Its queries may report errors (getUniform with another program's location): the
        # listener must not re-enter then, or a mutating handler changes what is being recorded.
        self.reentry_depth += 1
        try:
            return self._snapshot(side)
        finally:
            self.reentry_depth -= 1

    def _snapshot(self, side: Side):
        gl = side.gl
        state = [gl.getParameter(p) for p in side.pnames]
        for i in range(4):
            state += [gl.getVertexAttrib(i, p) for p in side.attrib_pnames]
            state.append(gl.getVertexAttribOffset(i, gl.VERTEX_ATTRIB_ARRAY_POINTER))
        for target in (gl.ARRAY_BUFFER, gl.ELEMENT_ARRAY_BUFFER):
            binding = gl.getParameter(gl.ARRAY_BUFFER_BINDING if target == gl.ARRAY_BUFFER
                                      else gl.ELEMENT_ARRAY_BUFFER_BINDING)
            state.append(gl.getBufferParameter(target, gl.BUFFER_SIZE) if binding is not None else None)
        prog = gl.getParameter(gl.CURRENT_PROGRAM)
        if prog is not None:
            state.append(gl.getProgramParameter(prog, gl.LINK_STATUS))
            for loc in side.objects["location"]:
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", softgl.GLWarning)
                        state.append(gl.getUniform(prog, loc))
                except softgl.GLError:
                    state.append("error")
        state.append(gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE))
        return state

    def _make_drawable(self, side: Side):
        """A plausible draw setup (program in use, attribute 0 fed from a buffer, indices), made
        of fuzzed calls too, so that the random stream reaches drawing often."""
        gl, R = side.gl, self.rng
        progs = side.objects["program"]
        bufs = side.objects["buffer"]
        if not progs or len(bufs) < 2:
            self._call(side, "createBuffer", ())
            return
        prog = progs[int(R.integers(len(progs)))]
        vbuf, ibuf = bufs[int(R.integers(len(bufs)))], bufs[int(R.integers(len(bufs)))]
        n = int(R.integers(3, 40))
        self._call(side, "useProgram", (prog,))
        self._call(side, "bindBuffer", (gl.ARRAY_BUFFER, vbuf))
        pos = R.uniform(-1.2, 1.2, (n, 4)).astype(np.float32)
        pos[:, 3] = 1
        self._call(side, "bufferData", (gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW))
        self._call(side, "enableVertexAttribArray", (0,))
        self._call(side, "vertexAttribPointer", (0, 4, gl.FLOAT, False, 0, 0))
        if R.random() < 0.5:
            self._call(side, "bindBuffer", (gl.ELEMENT_ARRAY_BUFFER, ibuf))
            idx = R.integers(0, n, int(R.integers(0, 60))).astype([np.uint8, np.uint16][int(R.integers(2))])
            self._call(side, "bufferData", (gl.ELEMENT_ARRAY_BUFFER, idx, gl.DYNAMIC_DRAW))
            self._call(side, "drawElements", (int(R.choice(MODES)), len(idx), 0x1401 if idx.itemsize == 1 else 0x1403, 0))
        else:
            self._call(side, "drawArrays", (int(R.choice(MODES)), int(R.integers(0, 3)), int(R.integers(0, n))))

    def _bounded(self, side: Side, name: str, args) -> tuple:
        if name == "readPixels" and abs(args[2] * args[3]) > 1 << 20:
            # A huge readPixels without a destination returns a new array of that size (or
            # OUT_OF_MEMORY beyond the memory budget, tested in tests/stress/test_resources.py);
            # gigabyte results would only make the fuzz run slow.
            return args[:2] + (min(args[2], 64), min(args[3], 64)) + args[4:]
        # Keep draws that no enabled attribute array bounds small (see MAX_UNBOUNDED_VERTICES).
        if not name.startswith("draw"):
            return args
        args = list(args)
        count_at = {"drawArrays": 2, "drawArraysInstanced": 2}.get(name, 1 if name != "drawRangeElements" else 3)
        instances = args[-1] if "Instanced" in name else 1
        work = (args[count_at] % 2**32) * max(1, instances % 2**32)
        if work <= MAX_UNBOUNDED_VERTICES:
            return tuple(args)
        gl = side.gl
        prog = gl.getParameter(gl.CURRENT_PROGRAM)
        bounded = False
        if prog is not None and gl.getProgramParameter(prog, gl.LINK_STATUS):
            for i in range(gl.getProgramParameter(prog, gl.ACTIVE_ATTRIBUTES)):
                loc = gl.getAttribLocation(prog, gl.getActiveAttrib(prog, i).name)
                if 0 <= loc and gl.getVertexAttrib(loc, gl.VERTEX_ATTRIB_ARRAY_ENABLED) and \
                        gl.getVertexAttrib(loc, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) is not None and \
                        (self.version == 1 or gl.getVertexAttrib(loc, gl.VERTEX_ATTRIB_ARRAY_DIVISOR) == 0):
                    bounded = True
        if not bounded:
            args[count_at] = MAX_UNBOUNDED_VERTICES
            if "Instanced" in name:
                args[-1] = 1
        return tuple(args)

    def step(self):
        R = self.rng
        r = R.random()
        if r < 0.02:
            self.reentrant = [None, "readonly", "mutating"][int(R.integers(3))]
            self.log.append(f"# re-entrant handler: {self.reentrant}")
            return
        side = self.sides[int(R.random() < 0.15)]
        if r < 0.04:
            side.strict = not side.strict
            self.log.append(f"# side {self.sides.index(side)} strict={side.strict}")
            return
        if r < 0.10:
            self._make_drawable(side)
            return
        name, args = self.make_call(side)
        self._call(side, name, args)

    def _call(self, side: Side, name: str, args):
        gl = side.gl
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            with _quiet_strict(side):
                args = self._bounded(side, name, args)
                before = self.snapshot(side)
                gl.getError()   # after the snapshot: its own queries must not leave an error pending
        self.reported.clear()
        self.calls += 1
        self.log.append(f"ctx{self.sides.index(side)}{'(strict)' if side.strict else ''}.{name}{_short(args)}")
        raised = None
        result = None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            warnings.simplefilter("ignore", softgl.Float64Warning)   # float64 bytes on purpose
            try:
                result = getattr(gl, name)(*args)
            except softgl.GLError as e:
                raised = e
            except TypeError as e:
                raised = e
            except BaseException as e:  # noqa: BLE001 - anything else breaks the contract
                raise self.violation(f"{name} raised {type(e).__name__}: {e}") from e
        reported = list(self.reported)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.GLWarning)
            with _quiet_strict(side):
                pending = gl.getError()
                after = self.snapshot(side)
        mutated_by_handler = self.reentrant == "mutating" and self.reentered and reported
        self.reentered = 0
        if isinstance(raised, TypeError):
            if reported:
                raise self.violation(f"{name} raised TypeError after reporting {reported}")
            if not _same(before, after):
                raise self.violation(f"{name} raised TypeError ({raised}) but changed the state")
            return
        if raised is not None and not side.strict:
            raise self.violation(f"{name} raised {raised} in a non-strict context")
        if side.strict and reported and raised is None:
            raise self.violation(f"{name} reported {reported} in a strict context but did not raise")
        if reported:
            self.errors += 1
            if name == "getError":
                raise self.violation("getError reported an error")
            if pending != reported[0] and self.reentrant is None:
                raise self.violation(f"{name}: getError() = {pending:#x}, but the call reported {reported}")
            if not mutated_by_handler and not _same(before, after):
                diff = _diff(before, after)
                raise self.violation(f"{name} reported {[hex(c) for c in reported]} but changed the state: {diff}")
        elif pending != 0 and name != "getError" and self.reentrant is None:
            raise self.violation(f"{name} recorded {pending:#x} without reporting it")
        self._track(side, name, args, result, reported)

    def _track(self, side: Side, name: str, args, result, reported):
        if name.startswith("create") and result is not None:
            kind = {"createBuffer": "buffer", "createProgram": "program", "createShader": "shader",
                    "createVertexArray": "vao"}[name]
            side.objects[kind].append(result)
        elif name.startswith("delete") and not reported and args and args[0] is not None:
            kind = {"deleteBuffer": "buffer", "deleteProgram": "program", "deleteShader": "shader",
                    "deleteVertexArray": "vao"}[name]
            pool = side.objects[kind]
            for i, o in enumerate(pool):
                if o is args[0]:
                    side.deleted[kind].append(pool.pop(i))
                    break
        elif name == "getUniformLocation" and result is not None:
            side.objects["location"].append(result)
        elif name == "linkProgram" and not reported and args[0] is not None:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", softgl.GLWarning)
                    if side.gl.getProgramParameter(args[0], side.gl.LINK_STATUS):
                        self._collect_locations(side, args[0])
                    side.gl.getError()
            except softgl.GLError:
                pass
        for kind, pool in side.objects.items():   # bounded pools
            del pool[:-24]
            del side.deleted[kind][:-12]

    def violation(self, message: str) -> Violation:
        tail = "\n".join(self.log[-40:])
        return Violation(f"{message}\nlast calls:\n{tail}")


class _quiet_strict:
    """Make the strict side non-raising while the fuzzer itself inspects state."""

    def __init__(self, side: Side):
        self.side = side

    def __enter__(self):
        self.strict, self.side.strict = self.side.strict, False

    def __exit__(self, *exc):
        self.side.strict = self.strict


def _short(args) -> str:
    parts = []
    for a in args:
        if isinstance(a, np.ndarray):
            parts.append(f"np.{a.dtype}{list(a.shape)}")
        elif isinstance(a, str):
            parts.append(repr(a if len(a) < 30 else a[:27] + "..."))
        elif isinstance(a, (int, float, bool, type(None))):
            parts.append(hex(a) if isinstance(a, int) and not isinstance(a, bool) and a > 0x1000 else repr(a))
        elif isinstance(a, list):
            parts.append(f"[{len(a)} values]")
        else:
            parts.append(type(a).__name__)
    return "(" + ", ".join(parts) + ")"


def _diff(a, b) -> str:
    out = []
    for i, (x, y) in enumerate(zip(a, b)):
        if not _same(x, y):
            out.append(f"#{i}: {x!r} -> {y!r}")
    return "; ".join(out[:4])
