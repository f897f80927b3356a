"""Where softgl may legitimately differ from Chromium's WebGL, and how to judge it instead.

Each rule is `rule(setup, entry, softgl_result, webgl_result)` and returns None (acceptable), a
reason string (mismatch), or NotImplemented (the rule does not apply; compare for equality).

- Implementation limits (MAX_*, ranges, ...): softgl must meet the ES 2.0 / ES 3.0 minimum (or
  maximum, for MIN_PROGRAM_TEXEL_OFFSET and UNIFORM_BUFFER_OFFSET_ALIGNMENT), not equal Chromium.
- VENDOR / RENDERER / VERSION / SHADING_LANGUAGE_VERSION: only WebGL's mandated prefix.
- Extensions: softgl may support fewer than Chromium, but never claim one Chromium's WebGL of
  that version does not have.
- NAN_UNSPECIFIED: state set from a NaN argument, which the ES spec leaves unspecified.
- CHROMIUM_DEVIATIONS: places where Chromium/ANGLE departs from the WebGL/ES spec; softgl follows
  the spec, and the test checks softgl against the spec's value.
"""
from __future__ import annotations

from recorder import ENUMS, decode_number, values_match

E = ENUMS["webgl2"]

# ES 2.0 §6.2 tables 6.18-6.20 (WebGL 1); ES 3.0 §6.2 tables 6.28-6.35 (WebGL 2).
# name: (">=", minimum) or ("<=", maximum)
LIMITS_V1 = {
    "MAX_VERTEX_ATTRIBS": (">=", 8), "MAX_VERTEX_UNIFORM_VECTORS": (">=", 128),
    "MAX_VARYING_VECTORS": (">=", 8), "MAX_COMBINED_TEXTURE_IMAGE_UNITS": (">=", 8),
    "MAX_VERTEX_TEXTURE_IMAGE_UNITS": (">=", 0), "MAX_TEXTURE_IMAGE_UNITS": (">=", 8),
    "MAX_FRAGMENT_UNIFORM_VECTORS": (">=", 16), "MAX_TEXTURE_SIZE": (">=", 64),
    "MAX_CUBE_MAP_TEXTURE_SIZE": (">=", 16), "MAX_RENDERBUFFER_SIZE": (">=", 1),
    "SUBPIXEL_BITS": (">=", 4),
}
LIMITS_V2 = {
    "MAX_ELEMENT_INDEX": (">=", 2**24 - 1), "SUBPIXEL_BITS": (">=", 4),
    "MAX_3D_TEXTURE_SIZE": (">=", 256), "MAX_TEXTURE_SIZE": (">=", 2048),
    "MAX_ARRAY_TEXTURE_LAYERS": (">=", 256), "MAX_TEXTURE_LOD_BIAS": (">=", 2.0),
    "MAX_CUBE_MAP_TEXTURE_SIZE": (">=", 2048), "MAX_RENDERBUFFER_SIZE": (">=", 2048),
    "MAX_DRAW_BUFFERS": (">=", 4), "MAX_COLOR_ATTACHMENTS": (">=", 4),
    "MAX_ELEMENTS_INDICES": (">=", 0), "MAX_ELEMENTS_VERTICES": (">=", 0),  # no ES minimum
    "MAX_SERVER_WAIT_TIMEOUT": (">=", 0), "MAX_CLIENT_WAIT_TIMEOUT_WEBGL": (">=", 0),
    "MAX_VERTEX_ATTRIBS": (">=", 16), "MAX_VERTEX_UNIFORM_COMPONENTS": (">=", 1024),
    "MAX_VERTEX_UNIFORM_VECTORS": (">=", 256), "MAX_VERTEX_UNIFORM_BLOCKS": (">=", 12),
    "MAX_VERTEX_OUTPUT_COMPONENTS": (">=", 64), "MAX_VERTEX_TEXTURE_IMAGE_UNITS": (">=", 16),
    "MAX_FRAGMENT_UNIFORM_COMPONENTS": (">=", 896), "MAX_FRAGMENT_UNIFORM_VECTORS": (">=", 224),
    "MAX_FRAGMENT_UNIFORM_BLOCKS": (">=", 12), "MAX_FRAGMENT_INPUT_COMPONENTS": (">=", 60),
    "MAX_TEXTURE_IMAGE_UNITS": (">=", 16), "MIN_PROGRAM_TEXEL_OFFSET": ("<=", -8),
    "MAX_PROGRAM_TEXEL_OFFSET": (">=", 7), "MAX_UNIFORM_BUFFER_BINDINGS": (">=", 24),
    "MAX_UNIFORM_BLOCK_SIZE": (">=", 16384), "UNIFORM_BUFFER_OFFSET_ALIGNMENT": ("<=", 256),
    "MAX_COMBINED_UNIFORM_BLOCKS": (">=", 24), "MAX_VARYING_COMPONENTS": (">=", 60),
    "MAX_VARYING_VECTORS": (">=", 15), "MAX_COMBINED_TEXTURE_IMAGE_UNITS": (">=", 32),
    "MAX_TRANSFORM_FEEDBACK_INTERLEAVED_COMPONENTS": (">=", 64),
    "MAX_TRANSFORM_FEEDBACK_SEPARATE_ATTRIBS": (">=", 4),
    "MAX_TRANSFORM_FEEDBACK_SEPARATE_COMPONENTS": (">=", 4), "MAX_SAMPLES": (">=", 4),
    # ES 3.0 table 6.34: at least MAX_*_UNIFORM_BLOCKS * MAX_UNIFORM_BLOCK_SIZE / 4 + components
    "MAX_COMBINED_VERTEX_UNIFORM_COMPONENTS": (">=", 12 * 16384 // 4 + 1024),
    "MAX_COMBINED_FRAGMENT_UNIFORM_COMPONENTS": (">=", 12 * 16384 // 4 + 896),
}
LIMITS = {1: {E[k]: (k, *v) for k, v in LIMITS_V1.items()},
          2: {E[k]: (k, *v) for k, v in LIMITS_V2.items()}}

# Ranges [lo, hi] that must contain 1 (ES 2.0 / 3.0: the minimum range is (1, 1)).
RANGES = {E["ALIASED_LINE_WIDTH_RANGE"], E["ALIASED_POINT_SIZE_RANGE"]}

# WebGL 1.0 §5.14.3 / WebGL 2.0 §3.7.2: the strings begin with these.
STRING_PREFIXES = {
    1: {E["VERSION"]: "WebGL 1.0", E["SHADING_LANGUAGE_VERSION"]: "WebGL GLSL ES 1.0",
        E["VENDOR"]: "", E["RENDERER"]: ""},
    2: {E["VERSION"]: "WebGL 2.0", E["SHADING_LANGUAGE_VERSION"]: "WebGL GLSL ES 3.00",
        E["VENDOR"]: "", E["RENDERER"]: ""},
}

# Chromium/ANGLE departures from the spec: (version, pname): (what Chromium says, the spec value).
CHROMIUM_DEVIATIONS = {
    # ES 3.0 §4.2.1 / table 6.13: on the default framebuffer DRAW_BUFFER0 is BACK and every other
    # DRAW_BUFFERi is NONE; Chromium answers BACK for all eight.
    **{(2, E["DRAW_BUFFER0"] + i): (E["BACK"], E["NONE"]) for i in range(1, 8)},
}


# ES 3.0 §2.1.1: a NaN argument gives an unspecified (harmless) result. Chromium stores 0 for
# clearColor/polygonOffset NaN (but keeps NaN for blendColor in WebGL 2); softgl may keep the NaN
# in these parameters. Only a NaN on softgl's side is excused, never a different number.
NAN_UNSPECIFIED = {E["COLOR_CLEAR_VALUE"], E["POLYGON_OFFSET_FACTOR"], E["POLYGON_OFFSET_UNITS"]}


def nan_rule(setup, entry, s, w):
    if entry["call"] != "getParameter" or not entry["args"] or entry["args"][0] not in NAN_UNSPECIFIED:
        return NotImplemented
    def is_nan(v):
        return isinstance(v, dict) and v.get("num") == "NaN"
    if isinstance(s, dict) and "values" in s and isinstance(w, dict) and "values" in w:
        if not any(map(is_nan, s["values"])) or len(s["values"]) != len(w["values"]):
            return NotImplemented
        rest = [(a, b) for a, b in zip(s["values"], w["values"]) if not is_nan(a)]
        return values_match([a for a, _ in rest], [b for _, b in rest])
    return None if is_nan(s) and _number(w) is not None else NotImplemented


def _number(v):
    v = decode_number(v)
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def limit_rule(setup, entry, s, w):
    if entry["call"] != "getParameter" or entry["error"] or not entry["args"]:
        return NotImplemented
    pname = entry["args"][0]
    if pname in LIMITS[setup.version]:
        name, op, bound = LIMITS[setup.version][pname]
        x = _number(s)
        if x is None or _number(w) is None:
            return f"{name}: expected a number, softgl {s!r}, webgl {w!r}"
        ok = x >= bound if op == ">=" else x <= bound
        return None if ok else f"{name} = {x}, spec requires {op} {bound}"
    if pname in RANGES or pname == E["MAX_VIEWPORT_DIMS"]:
        if not (isinstance(s, dict) and isinstance(w, dict) and s.get("type") == w.get("type")):
            return f"expected {w.get('type') if isinstance(w, dict) else w}, softgl {s!r}"
        values = [decode_number(v) for v in s["values"]]
        if len(values) != 2:
            return f"expected 2 values, softgl {values}"
        if pname in RANGES:
            return None if values[0] <= 1 <= values[1] else f"range {values} must contain 1"
        # ES 3.0 §2.12.1: at least as large as the visible surface
        need = max(setup.width, setup.height)
        return None if min(values) >= need else f"MAX_VIEWPORT_DIMS {values} < {need}"
    return NotImplemented


def string_rule(setup, entry, s, w):
    if entry["call"] != "getParameter" or entry["error"] or not entry["args"]:
        return NotImplemented
    prefix = STRING_PREFIXES[setup.version].get(entry["args"][0])
    if prefix is None:
        return NotImplemented
    if not isinstance(s, str) or not s:
        return f"expected a non-empty string, softgl {s!r}"
    return None if s.startswith(prefix) else f"{s!r} does not start with {prefix!r}"


def _all_webgl_extensions():
    # Names Chromium's WebGL knows (both versions), from the committed initial parameters.
    import json
    from recorder import REFERENCE
    p = json.loads((REFERENCE / "initial_parameters.json").read_text())
    return {n.lower() for v in ("v1", "v2") for n in p[v]["extensions"]}


WEBGL_EXTENSIONS = _all_webgl_extensions()


def extension_rule(setup, entry, s, w):
    if entry["call"] == "getSupportedExtensions":
        if not (isinstance(s, list) and all(isinstance(n, str) for n in s)):
            return f"expected a list of names, softgl {s!r}"
        # softgl's own (non-WebGL) extensions are not judged here
        extra = [n for n in s if n.lower() in WEBGL_EXTENSIONS and n not in (w or [])]
        return f"lists {extra}, which this WebGL version does not have" if extra else None
    if entry["call"] == "getExtension":
        # an optional extension softgl does not support is acceptable; the opposite is not
        return None if s == w or (s is False and w is True) else f"softgl {s}, webgl {w}"
    return NotImplemented


def deviation_rule(setup, entry, s, w):
    if entry["call"] != "getParameter" or not entry["args"]:
        return NotImplemented
    known = CHROMIUM_DEVIATIONS.get((setup.version, entry["args"][0]))
    if known is None or w != known[0]:
        return NotImplemented
    why = values_match(s, known[1])
    return f"spec value {known[1]} expected (Chromium deviates): {why}" if why else None


RULES = [deviation_rule, limit_rule, string_rule, extension_rule, nan_rule]
