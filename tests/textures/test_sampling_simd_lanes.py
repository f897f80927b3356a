"""Lane by lane: the SIMD depth-compare and cube-map paths of the sampler (surface/sampler.cpp
DepthTexels8, cube_coords8) against the general per-lane path, with every lane's coordinates
chosen one by one (read with texelFetch from an RGBA32F texture, so that they are exact): depth
references on a texel's depth and one ulp either side, below 0, above 1, +-0, infinite and NaN,
for every compare function, NEAREST and LINEAR, DEPTH_COMPONENT16 / 24 / 32F and
DEPTH24_STENCIL8; cube directions on faces, exactly on edges and corners (ties), +-0, huge,
tiny, infinite and NaN. Bits are compared (NaNs as NaNs) over the general path, the fast path
without SIMD, with AVX2 and with the best SIMD; independently, NEAREST lookups are checked
against the spec's rules computed here in float64 (ES 3.0 §3.8.16 and table 3.22 for the
comparison, §2.1.6 eq. 2.1 for the fixed-point depths, table 3.21 for the cube face)."""
import numpy as np
import pytest

import softgl
from helpers import VS3, draw_quad, float_target
from test_sampling_fast_path import PATHS, GENERAL, assert_same_bits, fast_queries, set_params, use_path

W, H = 40, 24   # 960 lanes: many whole blocks of 8 and 16
RNG = np.random.default_rng(2026)
COMPARE_FUNCS = ["LEQUAL", "GEQUAL", "LESS", "GREATER", "EQUAL", "NOTEQUAL", "ALWAYS", "NEVER"]


def lanes_fs(sampler, lookup):
    """Each fragment reads its lane's values (c) from unit 1 and looks `lookup` up in unit 0;
    lanes with c.w > 0.5 skip the lookup (inactive lanes inside SIMD blocks)."""
    return f"""#version 300 es
precision highp float;
uniform highp {sampler} tex;
uniform highp sampler2D lanes;
in vec3 uvw;
out vec4 color;
void main() {{
    vec4 c = texelFetch(lanes, ivec2(gl_FragCoord.xy), 0);
    color = vec4(-1.0);
    if (c.w < 0.5) color = vec4({lookup});
}}
"""


def render_all_paths(gl, source, lanes):
    """Draws with every sampler path; asserts equal bits and that the fast paths served the
    lookups; returns the general path's image."""
    gl.activeTexture(gl.TEXTURE1)
    data = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, data)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, W, H, 0, gl.RGBA, gl.FLOAT, lanes.astype(np.float32))
    set_params(gl, gl.TEXTURE_2D, "NEAREST", "NEAREST")
    gl.activeTexture(gl.TEXTURE0)
    prog = softgl.program(gl, VS3, source)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "tex"), 0)
    gl.uniform1i(gl.getUniformLocation(prog, "lanes"), 1)
    images = []
    for path in PATHS:
        use_path(gl, path)
        draw_quad(gl, prog)
        assert gl.getError() == gl.NO_ERROR
        assert (fast_queries(gl) > 0) == (path != GENERAL)
        images.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT))
    for img in images[1:]:
        assert_same_bits(img, images[0])
    gl.deleteTexture(data)
    return images[0]


# ---------------------------------------------------------------------------- depth compare

TW, TH = 16, 8   # powers of two: texel centres (i + 0.5) / TW are exact in float32

DEPTH_FORMATS = {   # internal format: (format, type, bits of the fixed-point word or None for float)
    "DEPTH_COMPONENT16": ("DEPTH_COMPONENT", "UNSIGNED_SHORT", 16),
    "DEPTH_COMPONENT24": ("DEPTH_COMPONENT", "UNSIGNED_INT", 24),
    "DEPTH_COMPONENT32F": ("DEPTH_COMPONENT", "FLOAT", None),
    "DEPTH24_STENCIL8": ("DEPTH_STENCIL", "UNSIGNED_INT_24_8", 24),
}


def depth_texture(gl, fmt):
    """A TW x TH depth texture with 0, the largest depth and random ones; returns the depths as
    float32 by the spec's rule (None where the upload converts, DEPTH_COMPONENT24 from 32-bit words)."""
    base, type_, bits = DEPTH_FORMATS[fmt]
    n = TW * TH
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    if bits is None:
        d = RNG.uniform(0, 1, n).astype(np.float32)
        d[:2] = (0.0, 1.0)
        data, depths = d, d.astype(np.float32)
    else:
        words = RNG.integers(0, 2 ** bits, n, dtype=np.uint64)
        words[:2] = (0, 2 ** bits - 1)
        depths = (words.astype(np.float64) / (2 ** bits - 1)).astype(np.float32)   # ES 3.0 eq. 2.1
        if fmt == "DEPTH_COMPONENT16":
            data = words.astype(np.uint16)
        elif fmt == "DEPTH24_STENCIL8":
            data = ((words << np.uint64(8)) | RNG.integers(0, 256, n, dtype=np.uint64)).astype(np.uint32)
        else:   # 32-bit unorm words, converted to 24 bits on upload: no spec check
            data = (words << np.uint64(8)).astype(np.uint32)
            depths = None
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, fmt), TW, TH, 0, getattr(gl, base), getattr(gl, type_),
                  data.reshape(TH, TW))
    return None if depths is None else depths.reshape(TH, TW)


def depth_lanes(depths, fmt):
    """(s, t, ref, inactive) per lane: texel centres and random / edge / non-finite coordinates;
    references on the texel's depth (if known) and around it, and the special values."""
    n = W * H
    i, j = RNG.integers(0, TW, n), RNG.integers(0, TH, n)
    s, t = (i + 0.5) / TW, (j + 0.5) / TH
    kind = RNG.integers(0, 10, n)
    s = np.where(kind == 7, RNG.uniform(-0.3, 1.3, n), s)
    t = np.where(kind == 7, RNG.uniform(-0.3, 1.3, n), t)
    odd = np.array([np.nan, np.inf, -np.inf, -0.0, 1.0, 0.0, 1e30])
    s = np.where(kind == 8, odd[RNG.integers(0, len(odd), n)], s)
    t = np.where(kind == 9, odd[RNG.integers(0, len(odd), n)], t)
    d = depths[j, i].astype(np.float32) if depths is not None else RNG.uniform(0, 1, n).astype(np.float32)
    specials = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1.0, -0.5, 1.5, 1.0000001, -1e-30], np.float32)
    choice = RNG.integers(0, 6, n)
    ref = np.select([choice == 0, choice == 1, choice == 2, choice == 3, choice == 4],
                    [d, np.nextafter(d, np.float32(np.inf)), np.nextafter(d, np.float32(-np.inf)),
                     specials[RNG.integers(0, len(specials), n)], RNG.uniform(-0.1, 1.1, n).astype(np.float32)],
                    RNG.uniform(0, 1, n).astype(np.float32)).astype(np.float32)
    inactive = (RNG.integers(0, 23, n) == 0).astype(np.float32)   # a few: blocks with inactive lanes
    lanes = np.stack([s, t, ref, inactive], axis=-1).astype(np.float32).reshape(H, W, 4)
    return lanes, i.reshape(H, W), j.reshape(H, W), (kind < 7).reshape(H, W)


def compare_spec(func, ref, d):
    """ES 3.0 table 3.22 in numpy (a NaN fails every comparison but NOTEQUAL)."""
    with np.errstate(invalid="ignore"):
        return {"LEQUAL": ref <= d, "GEQUAL": ref >= d, "LESS": ref < d, "GREATER": ref > d, "EQUAL": ref == d,
                "NOTEQUAL": ref != d, "ALWAYS": np.ones_like(d, bool), "NEVER": np.zeros_like(d, bool)}[func]


@pytest.mark.parametrize("fmt", list(DEPTH_FORMATS))
def test_depth_compare_lanes(fmt):
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    depths = depth_texture(gl, fmt)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE)
    source = lanes_fs("sampler2DShadow", "texture(tex, c.xyz)")
    checked = 0
    for func in COMPARE_FUNCS:
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_COMPARE_FUNC, getattr(gl, func))
        for filt in ("NEAREST", "LINEAR"):
            set_params(gl, gl.TEXTURE_2D, filt, filt, "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
            lanes, i, j, centred = depth_lanes(depths, fmt)
            img = render_all_paths(gl, source, lanes)
            active = lanes[..., 3] < 0.5
            assert (img[~active] == -1).all()
            if depths is None or filt != "NEAREST":
                continue
            # ES 3.0 §3.8.16: fixed-point formats clamp the reference to [0, 1] (NaN stays NaN).
            ref = lanes[..., 2]
            if fmt != "DEPTH_COMPONENT32F":
                with np.errstate(invalid="ignore"):
                    ref = np.where(ref < 0, np.float32(0), np.where(ref > 1, np.float32(1), ref))
            expected = compare_spec(func, ref, depths[j, i]).astype(np.float32)
            sel = centred & active
            np.testing.assert_array_equal(img[..., 0][sel], expected[sel])
            np.testing.assert_array_equal(img[..., 3][sel], expected[sel])   # vec4 of the float result
            checked += int(sel.sum())
    assert depths is None or checked > 5000


def test_depth_without_compare_lanes():
    # A depth texture read without the comparison (NEAREST, as depth is not filterable without
    # it): (d, 0, 0, 1) with d the spec's value of the word.
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    for fmt in ("DEPTH_COMPONENT16", "DEPTH24_STENCIL8", "DEPTH_COMPONENT32F"):
        depths = depth_texture(gl, fmt)
        set_params(gl, gl.TEXTURE_2D, "NEAREST", "NEAREST", "CLAMP_TO_EDGE", "CLAMP_TO_EDGE")
        lanes, i, j, centred = depth_lanes(depths, fmt)
        img = render_all_paths(gl, lanes_fs("sampler2D", "texture(tex, c.xy)"), lanes)
        sel = centred & (lanes[..., 3] < 0.5)
        np.testing.assert_array_equal(img[..., 0][sel].view(np.uint32), depths[j, i][sel].view(np.uint32))
        assert (img[..., 1][sel] == 0).all() and (img[..., 3][sel] == 1).all()


# ---------------------------------------------------------------------------- cube maps

def cube_directions():
    """(x, y, z, inactive) per lane: random directions, exact ties between axes (edges and
    corners) with every sign, zero components of either sign, huge, tiny, infinite and NaN."""
    n = W * H
    dirs = RNG.uniform(-1, 1, (n, 3))
    kind = RNG.integers(0, 8, n)
    # Ties: two components of equal magnitude and largest (kinds 1-3: edges), or all three
    # (kind 4: corners), with random signs.
    m = RNG.uniform(0.1, 3, n)
    signs = RNG.choice([-1.0, 1.0], (n, 3))
    small = RNG.uniform(-1, 1, n) * m * 0.99
    for k, (a, b) in enumerate(((0, 1), (0, 2), (1, 2)), start=1):
        sel = kind == k
        dirs[sel, a], dirs[sel, b], dirs[sel, 3 - a - b] = m[sel], m[sel], small[sel]
    sel = kind == 4
    dirs[sel] = m[sel, None]
    tie = (kind >= 1) & (kind <= 4)
    dirs[tie] *= signs[tie]
    specials = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e38, -1e38, 1e-45, -1e-45, 1.0, -1.0])
    sel = kind >= 5
    dirs[sel] = np.where(RNG.integers(0, 2, (int(sel.sum()), 3)) == 0,
                         specials[RNG.integers(0, len(specials), (int(sel.sum()), 3))], dirs[sel])
    dirs[:8] = [(1, 1, 1), (-1, -1, -1), (0, 0, 0), (-0.0, -0.0, -0.0), (1, -1, 0), (0, -1, 1), (np.nan, 0, 0),
                (np.inf, np.inf, 1)]
    inactive = (RNG.integers(0, 23, n) == 0).astype(np.float64)
    return np.concatenate([dirs, inactive[:, None]], axis=1).astype(np.float32).reshape(H, W, 4)


def face_spec(x, y, z):
    """Table 3.21 in float64: the face (ties to x then y, softgl's rule: README) and s, t."""
    x, y, z = (np.asarray(v, np.float64) for v in (x, y, z))
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    face = np.where((ax >= ay) & (ax >= az), np.where(x >= 0, 0, 1),
                    np.where(ay >= az, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    with np.errstate(invalid="ignore", divide="ignore"):
        return face, 0.5 * (sc / ma + 1), 0.5 * (tc / ma + 1)


@pytest.mark.parametrize("fmt", ["RGBA8", "RGBA16F"])
@pytest.mark.parametrize("min_filter,mag_filter", [("NEAREST", "NEAREST"), ("LINEAR", "LINEAR"),
                                                   ("LINEAR", "NEAREST"), ("LINEAR_MIPMAP_LINEAR", "LINEAR")])
def test_cube_lanes(min_filter, mag_filter, fmt):
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    size = 8
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    level, s = 0, size
    while s >= 1:
        for face in range(6):
            data = RNG.integers(0, 256, (s, s, 4), dtype=np.uint8)
            if fmt == "RGBA8":
                gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, level, gl.RGBA8, s, s, 0, gl.RGBA,
                              gl.UNSIGNED_BYTE, data)
            else:
                gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, level, gl.RGBA16F, s, s, 0, gl.RGBA,
                              gl.FLOAT, data.astype(np.float32) * 3.0 - 300.0)
        s, level = s // 2, level + 1
    set_params(gl, gl.TEXTURE_CUBE_MAP, min_filter, mag_filter)
    lanes = cube_directions()
    render_all_paths(gl, lanes_fs("samplerCube", "texture(tex, c.xyz)"), lanes)


def test_cube_face_selection_lanes():
    # Each face one colour (its index), NEAREST: the face of every finite, non-zero lane whose
    # texel lies inside its face (s, t in [0, 1): at s = 1 seamless NEAREST takes the next face's
    # texel) against table 3.21 in float64, ties and signed zeros included; all paths agree.
    gl = softgl.Context(8, 8, antialias=False)
    float_target(gl, W, H)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    for face in range(6):
        data = np.full((4, 4, 4), face, np.float32)
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, gl.RGBA32F, 4, 4, 0, gl.RGBA, gl.FLOAT, data)
    set_params(gl, gl.TEXTURE_CUBE_MAP, "NEAREST", "NEAREST")
    lanes = cube_directions()
    img = render_all_paths(gl, lanes_fs("samplerCube", "texture(tex, c.xyz)"), lanes)
    face, s, t = face_spec(lanes[..., 0], lanes[..., 1], lanes[..., 2])
    with np.errstate(invalid="ignore"):
        sel = (np.isfinite(lanes[..., :3]).all(-1) & (np.abs(lanes[..., :3]).max(-1) > 0) & (lanes[..., 3] < 0.5)
               & (s >= 0) & (s < 1) & (t >= 0) & (t < 1))
    ties = sel & (np.sort(np.abs(lanes[..., :3]), -1)[..., 1] == np.abs(lanes[..., :3]).max(-1))
    assert sel.sum() > 500 and ties.sum() > 50
    np.testing.assert_array_equal(img[..., 0][sel], face[sel].astype(np.float32))
