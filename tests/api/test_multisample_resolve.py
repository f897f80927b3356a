"""Multisample resolves with every sample's bytes known: readPixels of a multisampled drawing
buffer and blitFramebuffer from a multisampled RGBA8 renderbuffer (ES 3.0 §4.3.3: the samples of
a pixel become one value; how is the implementation's), against the rules written out in float64.

The samples are set one by one: SAMPLE_COVERAGE with value (s + 1) / S covers samples 0 .. s
(pipeline/sample_mask.cpp), so full-screen draws of images I_{S-1}, ..., I_0 (texelFetch of an
RGBA8 texture: a byte goes through as itself) with coverage S/S, ..., 1/S leave I_s in sample s.

- readPixels: the mean of the bytes rounded half up, floor(mean + 0.5) (docs/architecture.md,
  "Life of a draw call").
- blitFramebuffer: the general loop's value, each byte as the float k / 255, their mean in double
  in sample order, rounded to float, then to a byte as float_to_unorm8 does (surface/formats.h).
  Where the mean of the bytes lies exactly halfway between two bytes, the floats' rounding decides
  which: the tests check that such pixels occur and go both ways."""
import numpy as np
import pytest

import softgl

VS = """#version 300 es
in vec2 pos;
void main() { gl_Position = vec4(pos, 0.0, 1.0); }"""
FS = """#version 300 es
precision highp float; uniform highp sampler2D img; out vec4 o;
void main() { o = texelFetch(img, ivec2(gl_FragCoord.xy), 0); }"""


def sample_images(rng, samples, h, w):
    """(samples, h, w, 4) bytes: random, with whole rows of equal samples (no ties), rows of
    two values only (many ties) and the extremes."""
    imgs = rng.integers(0, 256, (samples, h, w, 4), dtype=np.uint8)
    imgs[:, 0] = imgs[0, 0]                                  # all samples equal
    imgs[:, 1, :, :] = np.where(np.arange(samples)[:, None, None] % 2 == 0, 0, 255)   # 0 / 255 alternating
    imgs[:, 2] = rng.integers(0, 256, (1, w, 4)) + np.arange(samples)[:, None, None] % 2   # k, k + 1
    imgs[:, 3] = 255
    return imgs


def set_samples(gl, imgs):
    """Draws sample s of every pixel of the bound framebuffer as imgs[s] (see the module doc)."""
    samples, h, w, _ = imgs.shape
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    loc = gl.getAttribLocation(prog, "pos")
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 3, -1, -1, 3], np.float32), gl.STATIC_DRAW)
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    gl.activeTexture(gl.TEXTURE0)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
    gl.uniform1i(gl.getUniformLocation(prog, "img"), 0)
    gl.enable(gl.SAMPLE_COVERAGE)
    for s in reversed(range(samples)):
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, np.ascontiguousarray(imgs[s]))
        gl.sampleCoverage((s + 1) / samples, False)
        gl.drawArrays(gl.TRIANGLES, 0, 3)
    gl.disable(gl.SAMPLE_COVERAGE)
    assert gl.getError() == gl.NO_ERROR


def rounded_mean(imgs):
    return np.floor(imgs.astype(np.float64).mean(axis=0) + 0.5).astype(np.uint8)


def float_mean_bytes(imgs):
    """The blit's rule, written out: float32(k) / 255 per sample, summed in float64 in sample
    order, divided by S, rounded to float32, then floor(v * 255 + 0.5) clamped to [0, 255]."""
    f = imgs.astype(np.float32) / np.float32(255)
    total = np.zeros(imgs.shape[1:], np.float64)
    for s in range(imgs.shape[0]):
        total = total + f[s].astype(np.float64)
    v = (total / imgs.shape[0]).astype(np.float32).astype(np.float64)
    return np.clip(np.floor(v * 255.0 + 0.5), 0, 255).astype(np.uint8)


# 203 x 170: more than 32,768 pixels and 16 rows (the pooled bands), and a width that is not a
# multiple of four (the SIMD loop's tail).
W, H = 203, 170


@pytest.mark.parametrize("samples", [2, 4, 8, 16])
@pytest.mark.parametrize("threads", [1, 2, 3])
def test_read_pixels_resolves_to_the_rounded_mean(samples, threads):
    imgs = sample_images(np.random.default_rng(samples), samples, H, W)
    gl = softgl.Context(W, H, version=2, antialias=True, samples=samples, threads=threads)
    set_samples(gl, imgs)
    expected = rounded_mean(imgs)
    np.testing.assert_array_equal(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), expected)
    # Rectangles partly outside the buffer: the outside stays as it was (zero).
    for x, y, w, h in ((-5, 7, 120, 190), (90, -3, 130, 60), (1, 1, 7, 33)):
        got = gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE)
        want = np.zeros((h, w, 4), np.uint8)
        xs, ys = slice(max(x, 0), min(x + w, W)), slice(max(y, 0), min(y + h, H))
        want[ys.start - y:ys.stop - y, xs.start - x:xs.stop - x] = expected[ys, xs]
        np.testing.assert_array_equal(got, want, err_msg=f"rect {(x, y, w, h)}")


def multisampled_framebuffer(gl, samples, w, h):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    rb = gl.createRenderbuffer()
    gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
    gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, gl.RGBA8, w, h)
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
    assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    return fb


def texture_framebuffer(gl, w, h):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, w, h)
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    return fb


@pytest.mark.parametrize("samples", [2, 4, 8, 16])
@pytest.mark.parametrize("dest", ["canvas", "canvas_no_alpha", "texture"])
@pytest.mark.parametrize("filt", ["NEAREST", "LINEAR"])
def test_blit_resolves_to_the_float_mean(samples, dest, filt):
    imgs = sample_images(np.random.default_rng(100 + samples), samples, H, W)
    expected = float_mean_bytes(imgs)
    # The halfway means occur and the float rule rounds them both ways: an integer rule would fail.
    ties = (imgs.astype(np.int64).sum(axis=0) % samples) == samples // 2
    assert ties.sum() > 100
    exact = rounded_mean(imgs)
    assert (expected[ties] != exact[ties]).any() and (expected[ties] == exact[ties]).any()
    assert (expected[~ties] == exact[~ties]).all()
    for threads in (1, 2, 3):
        for rows in (True, False):   # the row path (bands on the pool) and the general loop
            gl = softgl.Context(W, H, version=2, antialias=False, threads=threads, alpha=dest != "canvas_no_alpha")
            softgl._core.testing.set_tuning(gl, blit_rows=rows)
            src = multisampled_framebuffer(gl, samples, W, H)
            set_samples(gl, imgs)
            dst = texture_framebuffer(gl, W, H) if dest == "texture" else None
            # A part first (offset rows), over a cleared destination; then the whole.
            for x0, y0, x1, y1 in ((7, 5, 188, 150), (0, 0, W, H)):
                gl.bindFramebuffer(gl.FRAMEBUFFER, dst)
                gl.clearColor(0.0, 0.0, 0.0, 0.0)
                gl.clear(gl.COLOR_BUFFER_BIT)
                gl.bindFramebuffer(gl.READ_FRAMEBUFFER, src)
                gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, dst)
                gl.blitFramebuffer(x0, y0, x1, y1, x0, y0, x1, y1, gl.COLOR_BUFFER_BIT, getattr(gl, filt))
                assert gl.getError() == gl.NO_ERROR
                gl.bindFramebuffer(gl.FRAMEBUFFER, dst)
                got = gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE)
                want = np.zeros_like(expected)
                want[y0:y1, x0:x1] = expected[y0:y1, x0:x1]
                if dest == "canvas_no_alpha":
                    want[..., 3] = 255
                np.testing.assert_array_equal(got, want, err_msg=f"threads={threads} rows={rows} rect={(x0, y0, x1, y1)}")
