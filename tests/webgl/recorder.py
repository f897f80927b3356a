"""Write a WebGL scene once in Python; run it on softgl and replay it in Chromium's real WebGL.

A scene is a function `scene(gl)` that makes WebGL calls. `record(scene, version)` runs it on a
recording proxy: `gl.BLEND` gives the constant (from reference/enums.json, so a WebGL 1 proxy has no
`gl.MIN`, as in JS) and every method call is appended to a list. The list is then executed

  (a) on a softgl Context by `run_softgl(setup, calls)`, and
  (b) as JavaScript by `run_webgl([(setup, calls), ...])` (one Chromium page for all scenes),

and both give the same trace: a list of {call, args, error, result, thrown}, where `error` is
getError() right after the call and `result` is the encoded return value of getters and readPixels.
`compare(softgl_trace, webgl_trace)` lists readable mismatches.

Scenes must not branch on return values. Every call on the proxy returns a `Ref` to its result
(a WebGL object, a uniform location, an attribute location, an extension...): passed as an argument
it becomes {"ref": i} (i = the call's index) and both sides substitute the actual result of call i,
so `buf = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf)` replays in JS with a real
WebGLBuffer. Calling a method on a Ref (`ext.drawArraysInstancedANGLE(...)`) records the call with
"target": i. A scene reads a property such as drawingBufferWidth with
`gl.get_property("drawingBufferWidth")`.

Encoding (shared by both sides, JSON-safe): finite numbers, bools, strings and None as themselves;
NaN/Infinity/-Infinity as {"num": "NaN"} etc.; typed arrays as {"type": "Float32Array", "values": [...]}
(NumPy arrays in args become typed arrays of the matching type); dicts and lists recursively; WebGL
objects in results as {"object": "WebGLBuffer"} (the class name, the same on both sides).

Reference files keep long typed arrays (readPixels images) as {"type", "n", "zlib": base64 of the
zlib-compressed little-endian bytes}: `dump_traces` packs them, `load_traces` unpacks them.
"""
from __future__ import annotations

import base64
import inspect
import json
import zlib
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

REFERENCE = Path(__file__).resolve().parent / "reference"
ENUMS = json.loads((REFERENCE / "enums.json").read_text())

# NumPy dtype <-> JS typed array
TYPED_ARRAYS = {"int8": "Int8Array", "uint8": "Uint8Array", "int16": "Int16Array",
                "uint16": "Uint16Array", "int32": "Int32Array", "uint32": "Uint32Array",
                "float32": "Float32Array", "float64": "Float64Array"}
DTYPES = {v: np.dtype(k) for k, v in TYPED_ARRAYS.items()}

# Calls whose return value is part of the trace (all others return nothing in WebGL).
GETTERS = {"getParameter", "isEnabled", "getError", "getContextAttributes",
           "getSupportedExtensions", "getExtension", "isContextLost", "readPixels",
           # drawing scenes: compile/link status, locations and the objects create* returns
           "getShaderParameter", "getProgramParameter", "getAttribLocation", "getUniformLocation",
           "createBuffer", "createShader", "createProgram", "createVertexArray",
           "createVertexArrayOES"}


# ---------------------------------------------------------------------------- encoding

def encode(value):
    """A Python / softgl value in the JSON form both sides share."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)) and not isinstance(value, np.bool_):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else {"num": _js_number_name(value)}
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return {"type": TYPED_ARRAYS[value.dtype.name],
                "values": [encode(v) for v in value.ravel().tolist()]}
    if isinstance(value, (list, tuple)):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        return {k: encode(value[k]) for k in sorted(value)}
    if isinstance(value, Ref):
        return {"ref": value.index}
    if type(value).__name__.startswith("WebGL"):
        return {"object": type(value).__name__}
    raise TypeError(f"cannot encode {type(value).__name__} for WebGL replay")


def _js_number_name(x: float) -> str:
    return "NaN" if math.isnan(x) else ("Infinity" if x > 0 else "-Infinity")


def decode_number(value):
    if isinstance(value, dict) and "num" in value:
        return float(value["num"].replace("Infinity", "inf"))
    return value


def decode_arg(value, results=None):
    """An encoded argument back to the Python object the scene passed; {"ref": i} becomes
    `results[i]`, the value call i returned."""
    if isinstance(value, dict):
        if "ref" in value:
            return results[value["ref"]]
        if "num" in value:
            return decode_number(value)
        if "type" in value:
            arr = np.array([decode_number(v) for v in value["values"]], dtype=DTYPES[value["type"]])
            return arr.reshape(value.get("shape", arr.shape))
        return {k: decode_arg(v, results) for k, v in value.items()}
    if isinstance(value, list):
        return [decode_arg(v, results) for v in value]
    return value


# Typed arrays longer than this are stored zlib-compressed in reference files.
PACK_MIN = 64


def pack(value):
    """Long typed arrays in `value` (recursively) as {"type", "n", "zlib"}; the rest unchanged."""
    if isinstance(value, dict) and "type" in value and "values" in value \
            and len(value["values"]) > PACK_MIN \
            and not any(isinstance(v, dict) for v in value["values"]):
        raw = np.array(value["values"], dtype=DTYPES[value["type"]]).astype(
            DTYPES[value["type"]].newbyteorder("<")).tobytes()
        rest = {k: v for k, v in value.items() if k != "values"}      # type, shape
        return rest | {"n": len(value["values"]),
                       "zlib": base64.b64encode(zlib.compress(raw, 9)).decode()}
    if isinstance(value, dict):
        return {k: pack(v) for k, v in value.items()}
    if isinstance(value, list):
        return [pack(v) for v in value]
    return value


def unpack(value):
    """The inverse of `pack`."""
    if isinstance(value, dict) and "zlib" in value:
        raw = zlib.decompress(base64.b64decode(value["zlib"]))
        arr = np.frombuffer(raw, DTYPES[value["type"]].newbyteorder("<"))
        assert arr.size == value["n"]
        rest = {k: v for k, v in value.items() if k not in ("n", "zlib")}
        return rest | {"values": arr.tolist()}
    if isinstance(value, dict):
        return {k: unpack(v) for k, v in value.items()}
    if isinstance(value, list):
        return [unpack(v) for v in value]
    return value


def load_traces(path) -> dict:
    return unpack(json.loads(Path(path).read_text()))


# ---------------------------------------------------------------------------- scenes

@dataclass
class Setup:
    """How the context is made: part of the scene definition."""
    version: int
    width: int = 16
    height: int = 16
    # WebGL context attributes; antialias off and a preserved buffer make readPixels exact.
    attributes: dict = field(default_factory=lambda: dict(antialias=False,
                                                          preserveDrawingBuffer=True))

    def to_json(self):
        return {"version": self.version, "width": self.width, "height": self.height,
                "attributes": dict(sorted(self.attributes.items()))}


class Ref:
    """What a recorded call returns: its result, to pass on to later calls (see module doc)."""

    def __init__(self, calls: list, index: int):
        self._calls, self.index = calls, index

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)

        def call(*args):
            return _record_call(self._calls, name, args, target=self.index)
        return call

    def __repr__(self):
        return f"<result of call #{self.index}>"


class CallLog(list):
    """The recorded calls, plus an expectation waiting for the next call (see `expect`)."""
    pending = None


def _record_call(calls, name, args, target=None):
    # Copy arrays now: the scene may reuse them after the call.
    entry = {"call": name, "args": [_encode_arg(a) for a in args]}
    if target is not None:
        entry["target"] = target
    if calls.pending is not None:
        entry["expect"], calls.pending = calls.pending, None
    calls.append(entry)
    return Ref(calls, len(calls) - 1)


class RecordingContext:
    """Stands in for `gl` while a scene runs: constants come back, method calls are recorded."""

    def __init__(self, version: int):
        self._constants = ENUMS["webgl1" if version == 1 else "webgl2"]
        self._calls = CallLog()
        self.version = version

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        if name.isupper() or name[:1].isdigit():
            try:
                return self._constants[name]
            except KeyError:
                raise AttributeError(f"WebGL has no constant {name} in this version") from None

        def call(*args):
            return _record_call(self._calls, name, args)
        return call

    def expect(self, what: str):
        """Annotate the next call with a known, documented difference (entry["expect"]); the
        test decides what it accepts for it. Returns the context: gl.expect(X).drawArrays(...)"""
        self._calls.pending = what
        return self

    def get_property(self, name: str):
        """Read a context property (drawingBufferWidth, ...) at this point of the scene."""
        self._calls.append({"call": "@" + name, "args": []})


def _encode_arg(a):
    if isinstance(a, np.ndarray):
        out = encode(a)
        out["shape"] = list(a.shape)   # only softgl uses it; JS typed arrays are flat
        return out
    return encode(a)


def record(scene, version: int) -> list:
    """The calls `scene(gl)` or `scene(gl, version)` makes, for a context of this version."""
    gl = RecordingContext(version)
    if len(inspect.signature(scene).parameters) > 1:
        scene(gl, version)
    else:
        scene(gl)
    assert gl._calls.pending is None, "expect() must be followed by a call"
    return list(gl._calls)


def dump_traces(traces: dict, packed: bool = False) -> str:
    """JSON with one trace entry a line: small diffs when a reference is regenerated. `packed`
    compresses long typed arrays (see `pack`); read such files with `load_traces`."""
    if packed:
        traces = pack(traces)
    lines = ["{"]
    for n, (key, value) in enumerate(traces.items()):
        head = {k: v for k, v in value.items() if k != "trace"}
        lines.append(f" {json.dumps(key)}: {{")
        for k, v in head.items():
            lines.append(f"  {json.dumps(k)}: {json.dumps(v, allow_nan=False, sort_keys=True)},")
        lines.append('  "trace": [')
        trace = value["trace"]
        for i, entry in enumerate(trace):
            sep = "," if i + 1 < len(trace) else ""
            lines.append("   " + json.dumps(entry, allow_nan=False, sort_keys=True) + sep)
        lines.append("  ]")
        lines.append(" }" + ("," if n + 1 < len(traces) else ""))
    lines.append("}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- softgl side

def run_softgl(setup: Setup, calls: list) -> list:
    """Execute the recorded calls on a fresh softgl Context; return the trace."""
    import softgl
    gl = softgl.Context(setup.width, setup.height, version=setup.version, **setup.attributes)
    trace, results = [], []
    for entry in calls:
        name, args = entry["call"], [decode_arg(a, results) for a in entry["args"]]
        thrown, result = None, None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                if name.startswith("@"):
                    result = getattr(gl, name[1:])
                else:
                    target = gl if "target" not in entry else results[entry["target"]]
                    result = getattr(target, name)(*args)
            except Exception as exc:   # JS would throw too (TypeError ...): compare the name
                thrown = type(exc).__name__
        results.append(result)
        error = gl.getError()
        gl_warnings = [str(w.message) for w in caught if issubclass(w.category, softgl.GLWarning)]
        out = {"call": name, "args": entry["args"], "error": error,
               "result": _softgl_result(name, args, result), "thrown": thrown,
               "warnings": gl_warnings}
        if "target" in entry:
            out["target"] = entry["target"]
        trace.append(out)
    return trace


def _softgl_result(name, args, result):
    if name == "getExtension":
        return result is not None
    if name == "readPixels" and len(args) > 6:
        return encode(args[6])          # the caller's array after the call, as JS sees it
    if name in GETTERS or name.startswith("@"):
        return encode(result)
    return None


# ---------------------------------------------------------------------------- WebGL side

REPLAY_JS = r"""
const TYPES = {Int8Array, Uint8Array, Int16Array, Uint16Array, Int32Array, Uint32Array,
               Float32Array, Float64Array};
const GETTERS = new Set(%GETTERS%);
let RESULTS = [];   // raw return value of every call of the current scene, for {ref: i}
function decodeArg(a) {
  if (a === null || typeof a !== 'object') return a;
  if (Array.isArray(a)) return a.map(decodeArg);
  if ('ref' in a) return RESULTS[a.ref];
  if ('num' in a) return Number(a.num);
  if ('type' in a) return new TYPES[a.type](a.values.map(decodeArg));
  const o = {};
  for (const k of Object.keys(a)) o[k] = decodeArg(a[k]);
  return o;
}
function encode(v) {
  if (v === null || v === undefined) return null;
  if (typeof v === 'number') return Number.isFinite(v) ? v : {num: String(v)};
  if (typeof v === 'boolean' || typeof v === 'string') return v;
  if (ArrayBuffer.isView(v)) return {type: v.constructor.name, values: Array.from(v, encode)};
  if (Array.isArray(v)) return v.map(encode);
  if (typeof v === 'object' && Object.getPrototypeOf(v) === Object.prototype) {
    const o = {};
    for (const k of Object.keys(v).sort()) o[k] = encode(v[k]);
    return o;
  }
  return {object: v.constructor.name};   // WebGLBuffer etc.
}
// readPixels without a destination (softgl returns a new array): read into a buffer laid out by
// the PACK_* state, then keep the tightly packed h x w x channels block softgl returns.
const CHANNELS = {0x1906: 1, 0x1907: 3, 0x1908: 4, 0x1903: 1, 0x8227: 2, 0x8D94: 1, 0x8228: 2,
                  0x8D98: 3, 0x8D99: 4};
const PIXEL_ARRAY = {0x1401: Uint8Array, 0x1400: Int8Array, 0x1403: Uint16Array, 0x1402: Int16Array,
                     0x1405: Uint32Array, 0x1404: Int32Array, 0x1406: Float32Array,
                     0x8D61: Uint16Array, 0x8363: Uint16Array, 0x8033: Uint16Array, 0x8034: Uint16Array,
                     0x8368: Uint32Array, 0x8C3B: Uint32Array, 0x8C3E: Uint32Array};
function readPixelsNew(gl, x, y, w, h, format, type) {
  const T = PIXEL_ARRAY[type] || Uint8Array;
  const packed = [0x8363, 0x8033, 0x8034, 0x8368, 0x8C3B, 0x8C3E].includes(type);
  const n = packed ? 1 : (CHANNELS[format] || 4);
  const bpp = n * T.BYTES_PER_ELEMENT;
  const v2 = gl instanceof WebGL2RenderingContext;
  const align = gl.getParameter(gl.PACK_ALIGNMENT);
  const rowLength = v2 ? gl.getParameter(gl.PACK_ROW_LENGTH) : 0;
  const skipRows = v2 ? gl.getParameter(gl.PACK_SKIP_ROWS) : 0;
  const skipPixels = v2 ? gl.getParameter(gl.PACK_SKIP_PIXELS) : 0;
  const W = Math.max(w, 0), H = Math.max(h, 0);
  const stride = Math.ceil((rowLength > 0 ? rowLength : W) * bpp / align) * align;
  const bytes = (skipRows + H) * stride + (skipPixels + W) * bpp + 64;
  const buf = new T(Math.ceil(bytes / T.BYTES_PER_ELEMENT));
  gl.readPixels(x, y, w, h, format, type, buf);
  const out = new T(W * H * n);
  const u8 = new Uint8Array(buf.buffer), o8 = new Uint8Array(out.buffer);
  for (let r = 0; r < H; ++r) {
    const src = (skipRows + r) * stride + skipPixels * bpp;
    o8.set(u8.subarray(src, src + W * bpp), r * W * bpp);
  }
  return out;
}
function runScene(scene) {
  const canvas = document.createElement('canvas');
  canvas.width = scene.setup.width; canvas.height = scene.setup.height;
  const gl = canvas.getContext(scene.setup.version == 1 ? 'webgl' : 'webgl2',
                               scene.setup.attributes);
  const trace = [];
  RESULTS = [];
  for (const c of scene.calls) {
    const args = c.args.map(decodeArg);
    const target = c.target === undefined ? gl : RESULTS[c.target];
    let result = null, thrown = null, raw = null;
    try {
      if (c.call.startsWith('@')) {
        result = encode(gl[c.call.slice(1)]);
      } else if (c.call == 'readPixels' && args.length == 6) {
        result = readPixelsNew(gl, ...args);
      } else {
        const r = raw = target[c.call](...args);
        if (c.call == 'getExtension') result = r !== null;
        else if (c.call == 'readPixels') result = encode(args[6]);
        else if (GETTERS.has(c.call)) result = encode(r);
      }
    } catch (e) {
      thrown = e.name;
    }
    RESULTS.push(raw === undefined ? null : raw);
    const error = gl.getError();
    if (c.call == 'readPixels' && args.length == 6) result = error ? null : encode(result);
    const entry = {call: c.call, args: c.args, error, result, thrown};
    if (c.target !== undefined) entry.target = c.target;
    trace.push(entry);
  }
  const lose = gl.getExtension('WEBGL_lose_context');   // free it: Chromium caps live contexts
  if (lose) lose.loseContext();
  return trace;
}
result = {};
for (const scene of SCENES) result[scene.id] = runScene(scene);
"""


def webgl_script(scenes: dict) -> str:
    """JavaScript that replays {id: (setup, calls)} and assigns {id: trace} to `result`."""
    payload = [{"id": k, "setup": s.to_json(), "calls": c} for k, (s, c) in scenes.items()]
    return ("const SCENES = " + json.dumps(payload, allow_nan=False) + ";\n" +
            REPLAY_JS.replace("%GETTERS%", json.dumps(sorted(GETTERS))))


def run_webgl(scenes: dict) -> dict:
    """Replay {id: (setup, calls)} in headless Chromium; return {id: trace}."""
    from chromium import run_script
    return run_script(webgl_script(scenes), timeout=600)


# ---------------------------------------------------------------------------- comparison

def float32_close(a: float, b: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= 2.0 ** -23 * max(abs(a), abs(b), 2.0 ** -126)


def _is_number(v):
    return (isinstance(v, (int, float)) and not isinstance(v, bool)) or \
        (isinstance(v, dict) and "num" in v)


def values_match(a, b) -> str | None:
    """None when `a` (softgl) matches `b` (WebGL); else why not."""
    if _is_number(a) and _is_number(b):
        x, y = decode_number(a), decode_number(b)
        if isinstance(x, int) and isinstance(y, int):
            return None if x == y else f"{x} != {y}"
        return None if float32_close(float(x), float(y)) else f"{x!r} != {y!r}"
    if isinstance(a, dict) and isinstance(b, dict) and "type" in a and "type" in b:
        if a["type"] != b["type"]:
            return f"{a['type']} != {b['type']}"
        if len(a["values"]) != len(b["values"]):
            return f"length {len(a['values'])} != {len(b['values'])}"
        for i, (x, y) in enumerate(zip(a["values"], b["values"])):
            why = values_match(x, y)
            if why:
                return f"[{i}]: {why}  (softgl {_short(a['values'])}, webgl {_short(b['values'])})"
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"length {len(a)} != {len(b)}: {_short(a)} vs {_short(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            why = values_match(x, y)
            if why:
                return f"[{i}]: {why}"
        return None
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"key {k!r} only in {'softgl' if k in a else 'webgl'}"
            why = values_match(a[k], b[k])
            if why:
                return f"{k}: {why}"
        return None
    if type(a) is not type(b):
        return f"{_short(a)} ({_kind(a)}) != {_short(b)} ({_kind(b)})"
    return None if a == b else f"{_short(a)} != {_short(b)}"


def _kind(v):
    if _is_number(v):
        return "number"
    if isinstance(v, dict) and "type" in v:
        return v["type"]
    return {type(None): "null", bool: "bool", str: "string", list: "array",
            dict: "object"}.get(type(v), type(v).__name__)


def _short(v, n=80):
    s = json.dumps(v)
    return s if len(s) <= n else s[:n] + "..."


def pixels_match(a, b, tolerance: int = 1) -> str | None:
    """readPixels arrays: equal within `tolerance` (1/255 for bytes); else share equal and max diff."""
    if a is None or b is None or not (isinstance(a, dict) and isinstance(b, dict)):
        return values_match(a, b)
    if a["type"] != b["type"] or len(a["values"]) != len(b["values"]):
        return f"{a['type']}[{len(a['values'])}] != {b['type']}[{len(b['values'])}]"
    x = np.array([decode_number(v) for v in a["values"]], dtype=np.float64)
    y = np.array([decode_number(v) for v in b["values"]], dtype=np.float64)
    diff = np.abs(x - y)
    if diff.size == 0 or diff.max() <= tolerance:
        return None
    bad = np.flatnonzero(diff > tolerance)
    # RGBA data: a pixel is equal when its 4 values are
    pixels = diff.reshape(-1, 4) if diff.size % 4 == 0 else diff.reshape(-1, 1)
    return (f"{np.mean((pixels == 0).all(axis=1)):.1%} of pixels equal, max diff {diff.max():g}, "
            f"{bad.size} beyond {tolerance}; first at element {bad[0]}: "
            f"softgl {x[bad[0]]:g} vs webgl {y[bad[0]]:g}")


@dataclass
class PixelStats:
    """Agreement of the readPixels results of one trace pair (counted per RGBA pixel)."""
    pixels: int = 0        # pixels compared
    equal: int = 0         # all 4 bytes equal
    within: int = 0        # all 4 bytes within the tolerance
    max_diff: int = 0      # largest difference of one byte

    def __iadd__(self, other):
        self.pixels += other.pixels
        self.equal += other.equal
        self.within += other.within
        self.max_diff = max(self.max_diff, other.max_diff)
        return self

    def share(self, what="within"):
        return getattr(self, what) / self.pixels if self.pixels else 1.0


def pixel_stats(softgl_trace, webgl_trace, tolerance: int = 1) -> PixelStats:
    """Compare every readPixels image both traces have (same size) pixel by pixel."""
    out = PixelStats()
    for s, w in zip(softgl_trace, webgl_trace):
        a, b = s["result"], w["result"]
        if s["call"] != "readPixels" or not (isinstance(a, dict) and isinstance(b, dict)) \
                or len(a["values"]) != len(b["values"]) or len(a["values"]) % 4:
            continue
        diff = np.abs(np.array(a["values"], np.int64) - np.array(b["values"], np.int64))
        per_pixel = diff.reshape(-1, 4).max(axis=1)
        out += PixelStats(per_pixel.size, int((per_pixel == 0).sum()),
                          int((per_pixel <= tolerance).sum()),
                          int(per_pixel.max()) if per_pixel.size else 0)
    return out


@dataclass
class Mismatch:
    index: int
    call: str
    args: list
    what: str       # error / result / thrown / sequence
    detail: str

    def __str__(self):
        return f"#{self.index} {self.call}({_args_text(self.args)}): {self.what}: {self.detail}"


def _args_text(args):
    out = []
    for a in args:
        if isinstance(a, dict) and "type" in a:
            out.append(f"{a['type']}[{len(a['values'])}]")
        elif isinstance(a, dict) and "num" in a:
            out.append(a["num"])
        elif isinstance(a, int) and not isinstance(a, bool) and a >= 0x100:
            out.append(_enum_name(a))
        else:
            out.append(json.dumps(a))
    return ", ".join(out)


_ENUM_NAMES = {}
for _name, _value in sorted(ENUMS["webgl2"].items()):
    _ENUM_NAMES.setdefault(_value, _name)


def _enum_name(v):
    return _ENUM_NAMES.get(v, hex(v))


# A rule decides a call's result instead of equality: rule(setup, softgl_entry, softgl_result,
# webgl_result) -> None when acceptable, a reason when not, NotImplemented when it does not apply.
def compare(softgl_trace, webgl_trace, setup: Setup | None = None, rules=()) -> list[Mismatch]:
    """Mismatches between the two traces of one scene (empty when they agree)."""
    out = []
    if [e["call"] for e in softgl_trace] != [e["call"] for e in webgl_trace]:
        return [Mismatch(-1, "", [], "sequence", "the traces are of different call lists")]
    for i, (s, w) in enumerate(zip(softgl_trace, webgl_trace)):
        def add(what, detail):
            out.append(Mismatch(i, s["call"], s["args"], what, detail))
        if s["thrown"] != w["thrown"]:
            add("thrown", f"softgl {s['thrown']}, webgl {w['thrown']}")
        if s["error"] != w["error"]:
            add("error", f"softgl {_error_name(s['error'])}, webgl {_error_name(w['error'])}")
        verdict = NotImplemented
        for rule in rules:
            verdict = rule(setup, s, s["result"], w["result"])
            if verdict is not NotImplemented:
                break
        if verdict is NotImplemented:
            verdict = (pixels_match if s["call"] == "readPixels" else values_match)(
                s["result"], w["result"])
        if verdict:
            add("result", verdict)
    return out


def _error_name(code):
    return {0: "NO_ERROR", 0x500: "INVALID_ENUM", 0x501: "INVALID_VALUE",
            0x502: "INVALID_OPERATION", 0x505: "OUT_OF_MEMORY",
            0x506: "INVALID_FRAMEBUFFER_OPERATION", 0x9242: "CONTEXT_LOST_WEBGL"}.get(code, hex(code))
