"""blitFramebuffer's row path (api/framebuffers.cpp blit_rows: 1:1 copies and multisample resolves,
row by row on the thread pool) against the general per-pixel loop (Tuning blit_rows=False, the
reference): random rectangles (offset, reversed on both sides, flipped, scaled, partly outside
either buffer), scissor, colour mask, formats, sample counts, destinations (the drawing buffer,
one or two textures), depth and stencil, at 1, 2 and 3 threads. The bytes must be the same."""
import numpy as np
import pytest

import softgl
from softgl import _core
from softgl.testing import tuned

W, H = 224, 160   # above the row path's pool threshold (32768 pixels): bands run on the pool

VS = """#version 300 es
in vec2 pos; in vec4 col; out vec4 v_col;
void main() { v_col = col; gl_Position = vec4(pos, col.x * 0.5 - 0.25, 1.0); }"""
FS_FLOAT = """#version 300 es
precision highp float; in vec4 v_col; out vec4 o;
void main() { o = v_col; }"""
FS_UINT = """#version 300 es
precision highp float; in vec4 v_col; out uvec4 o;
void main() { o = uvec4(abs(v_col) * 70000.0); }"""

# internal format, readPixels format / type, renderbuffer samples to try, value range drawn
FORMATS = {
    "RGBA8": ("RGBA", "UNSIGNED_BYTE", (1, 2, 4), (0.0, 1.0)),
    "SRGB8_ALPHA8": ("RGBA", "UNSIGNED_BYTE", (1, 4), (0.0, 1.0)),
    "RGBA16F": ("RGBA", "FLOAT", (1, 4), (-3.0, 4.0)),
    "RGBA32F": ("RGBA", "FLOAT", (1, 4), (-3.0, 4.0)),
    "RGBA8UI": ("RGBA_INTEGER", "UNSIGNED_INT", (1,), (0.0, 1.0)),
}


def draw_triangles(gl, rng, lo, hi, integer):
    """Random overlapping triangles with per-vertex colours (partial coverage at the edges gives
    the resolves non-trivial means) and depth / stencil writes."""
    prog = softgl.program(gl, VS, FS_UINT if integer else FS_FLOAT)
    gl.useProgram(prog)
    n = 12
    pos = rng.uniform(-1.3, 1.3, (n * 3, 2)).astype(np.float32)
    col = rng.uniform(lo, hi, (n * 3, 4)).astype(np.float32)
    for data, name, size in ((pos, "pos", 2), (col, "col", 4)):
        loc = gl.getAttribLocation(prog, name)
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 0, 0)
    gl.enable(gl.DEPTH_TEST)
    gl.enable(gl.STENCIL_TEST)
    gl.stencilOp(gl.KEEP, gl.INCR, gl.INCR)
    gl.drawArrays(gl.TRIANGLES, 0, n * 3)
    gl.disable(gl.DEPTH_TEST)
    gl.disable(gl.STENCIL_TEST)


def source_framebuffer(gl, fmt, samples, rng):
    """A framebuffer with a `fmt` colour and a DEPTH24_STENCIL8 renderbuffer of `samples`, drawn."""
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    for internal, attachment in ((getattr(gl, fmt), gl.COLOR_ATTACHMENT0), (gl.DEPTH24_STENCIL8, gl.DEPTH_STENCIL_ATTACHMENT)):
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        if samples > 1:
            gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, internal, W, H)
        else:
            gl.renderbufferStorage(gl.RENDERBUFFER, internal, W, H)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, attachment, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    lo, hi = FORMATS[fmt][3]
    draw_triangles(gl, rng, lo, hi, fmt.endswith("UI"))
    return fb


def texture_framebuffer(gl, fmt, count, w, h):
    """A framebuffer drawing into `count` textures of `fmt` (w x h) and a depth-stencil renderbuffer."""
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    textures = []
    for i in range(count):
        tex = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, tex)
        gl.texStorage2D(gl.TEXTURE_2D, 1, getattr(gl, fmt), w, h)
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, tex, 0)
        textures.append(tex)
    gl.drawBuffers([gl.COLOR_ATTACHMENT0 + i for i in range(count)])
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, w, h)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb


def random_rectangles(rng, samples, n):
    """(src, dst) rectangles: mostly 1:1 (the row path), some flipped or scaled (general in both runs)."""
    out = [((0, 0, W, H), (0, 0, W, H))]
    for k in range(n):
        x0, y0 = (int(v) for v in rng.integers(-20, 60, 2))
        w, h = (int(v) for v in rng.integers(1, 240, 2))
        src = (x0, y0, x0 + w, y0 + h)
        if samples > 1:   # a resolve needs identical rectangles
            dst = src
        else:
            ox, oy = (int(v) for v in rng.integers(-40, 40, 2))
            dst = (x0 + ox, y0 + oy, x0 + ox + w, y0 + oy + h)
            if k % 5 == 1:
                src, dst = (src[2], src[3], src[0], src[1]), (dst[2], dst[3], dst[0], dst[1])
            elif k % 5 == 2:
                dst = (dst[2], dst[1], dst[0], dst[3])   # flipped in x: the general path
            elif k % 5 == 3:
                dst = (dst[0], dst[1], dst[0] + w + 3, dst[3])   # scaled: the general path
        out.append((src, dst))
    return out


def run_blits(threads, fmt, samples, dest, filt, seed, blit_rows):
    """Every blit of the scenario into a freshly cleared destination; returns the bytes read back."""
    rng = np.random.default_rng(seed)
    integer = fmt.endswith("UI")
    canvas = dest.startswith("canvas")
    gl = softgl.Context(W - 16, H + 8, version=2, antialias=False, threads=threads, depth=True, stencil=True,
                        alpha=dest != "canvas_no_alpha", color_format="rgba16f" if dest == "canvas_16f" else "rgba8")
    if fmt in ("RGBA16F", "RGBA32F"):
        assert gl.getExtension("EXT_color_buffer_float") is not None
    src_fb = source_framebuffer(gl, fmt, samples, rng)
    dst_fb = None if canvas else texture_framebuffer(gl, fmt, 2 if dest == "two_textures" else 1, W + 8, H - 16)
    read_format, read_type = (getattr(gl, n) for n in FORMATS[fmt][:2])
    if canvas:
        read_format, read_type = gl.RGBA, gl.FLOAT if dest == "canvas_16f" else gl.UNSIGNED_BYTE
    rects = random_rectangles(rng, samples, 10)
    out = []
    with tuned(gl, blit_rows=blit_rows):
        for k, (src, dst) in enumerate(rects):
            gl.bindFramebuffer(gl.FRAMEBUFFER, dst_fb)
            gl.disable(gl.SCISSOR_TEST)
            gl.colorMask(True, True, True, True)
            if integer:
                gl.clearBufferuiv(gl.COLOR, 0, [7, 8, 9, 10])
                if dest == "two_textures":
                    gl.clearBufferuiv(gl.COLOR, 1, [7, 8, 9, 10])
            else:
                gl.clearColor(0.1, 0.2, 0.3, 0.4)
                gl.clear(gl.COLOR_BUFFER_BIT)
            gl.clearDepth(0.3)
            gl.clearStencil(5)
            gl.clear(gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT)
            if k % 4 == 2:
                sx, sy = (int(v) for v in rng.integers(0, 80, 2))
                gl.enable(gl.SCISSOR_TEST)
                gl.scissor(sx, sy, int(rng.integers(1, 200)), int(rng.integers(1, 150)))
            if k % 4 == 3:
                gl.colorMask(True, False, True, False)   # blits ignore the colour mask (both paths)
            mask = gl.COLOR_BUFFER_BIT
            if filt == "NEAREST" and k % 2 == 0:
                mask |= gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT
            gl.bindFramebuffer(gl.READ_FRAMEBUFFER, src_fb)
            gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, dst_fb)
            gl.blitFramebuffer(*src, *dst, mask, getattr(gl, filt))
            assert gl.getError() == gl.NO_ERROR, (src, dst)
            gl.bindFramebuffer(gl.FRAMEBUFFER, dst_fb)
            gl.disable(gl.SCISSOR_TEST)
            gl.colorMask(True, True, True, True)
            w, h = (gl.drawingBufferWidth, gl.drawingBufferHeight) if canvas else (W + 8, H - 16)
            for i in range(2 if dest == "two_textures" else 1):
                if not canvas:
                    gl.readBuffer(gl.COLOR_ATTACHMENT0 + i)
                pixels = gl.readPixels(0, 0, w, h, read_format, read_type)
                out.append(np.asarray(pixels).view(np.uint8).copy())
            if not canvas:   # the destination's depth / stencil, through a (general) blit to the canvas
                with tuned(gl, blit_rows=False):
                    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, dst_fb)
                    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, None)
                    gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT, gl.NEAREST)
            out.append(np.asarray(_core.testing.read_depth(gl._ctx if hasattr(gl, "_ctx") else gl)).copy())
            out.append(np.asarray(_core.testing.read_stencil(gl._ctx if hasattr(gl, "_ctx") else gl)).copy())
    return out


CASES = [(fmt, s, dest, filt)
         for fmt, (_, _, sample_counts, _) in FORMATS.items()
         for s in sample_counts
         for dest in (("texture", "two_textures") if fmt.endswith("UI") else
                      ("canvas", "canvas_no_alpha", "canvas_16f", "texture", "two_textures"))
         for filt in (("NEAREST",) if fmt.endswith("UI") else ("NEAREST", "LINEAR"))]


@pytest.mark.parametrize("fmt,samples,dest,filt", CASES)
def test_row_path_gives_the_general_paths_bytes(fmt, samples, dest, filt):
    seed = abs(hash((fmt, samples, dest, filt))) % 1000
    reference = run_blits(1, fmt, samples, dest, filt, seed, blit_rows=False)
    for threads in (1, 2, 3):
        got = run_blits(threads, fmt, samples, dest, filt, seed, blit_rows=True)
        assert len(got) == len(reference)
        for k, (a, b) in enumerate(zip(got, reference)):
            np.testing.assert_array_equal(a, b, err_msg=f"threads={threads} read {k}")

