"""Memory accounting across objects (docs/reliability.md, "Memory"): the limit bounds the sum of
all buffers, textures, renderbuffers and drawing buffers, not each call alone; going over records OUT_OF_MEMORY, warns and
changes nothing. Each case runs in a child interpreter with a small process-wide limit, and reads
the child's peak RSS (VmHWM) to show that a refused allocation was not made."""
import os
import subprocess
import sys

import softgl

MiB = 1 << 20
HERE = os.path.dirname(__file__)

PRELUDE = """
import warnings, softgl
warnings.simplefilter('ignore')
def vm_hwm():
    for line in open('/proc/self/status'):
        if line.startswith('VmHWM:'): return int(line.split()[1]) * 1024
"""


def run_child(code: str):
    r = subprocess.run([sys.executable, "-c", PRELUDE + code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_six_buffers_together_are_bounded_by_one_limit():
    # Each 100 MiB buffer passes a per-call check against a 300 MiB limit; together the fourth
    # must be refused and the peak RSS must stay near 3 x 100 MiB.
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False)
base = softgl._core.memory_in_use()                     # the drawing buffer
softgl._core.set_memory_limit(base + (300 << 20))
errors = []
for i in range(6):
    b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
    gl.bufferData(gl.ARRAY_BUFFER, 100 << 20, gl.STATIC_DRAW)
    errors.append(gl.getError())
    globals()['keep%d' % i] = b
print(*errors, softgl._core.memory_in_use() - base, vm_hwm())
""")
    errors = [int(e) for e in out[:6]]
    assert errors == [softgl.NO_ERROR] * 3 + [softgl.OUT_OF_MEMORY] * 3
    assert int(out[6]) == 300 * MiB
    assert int(out[7]) < 300 * MiB + 150 * MiB


def test_big_multisample_renderbuffer_is_out_of_memory_and_keeps_the_old_storage():
    # 16384 x 16384 x 4 samples of RGBA8 is 4 GiB (4 bytes a sample): over a 128 MiB limit. The
    # renderbuffer keeps its 64 x 64 storage and its bytes in the ledger.
    out = run_child("""
softgl._core.set_memory_limit(128 << 20)
gl = softgl.Context(4, 4, antialias=False, version=2)
rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, gl.RGBA8, 64, 64)
before = softgl._core.memory_in_use()
gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, gl.RGBA8, 16384, 16384)
e = gl.getError()
w = gl.getRenderbufferParameter(gl.RENDERBUFFER, gl.RENDERBUFFER_WIDTH)
s = gl.getRenderbufferParameter(gl.RENDERBUFFER, gl.RENDERBUFFER_SAMPLES)
print(e, w, s, softgl._core.memory_in_use() - before, vm_hwm())
""")
    assert int(out[0]) == softgl.OUT_OF_MEMORY
    assert [int(x) for x in out[1:4]] == [64, 4, 0]   # nothing changed
    assert int(out[4]) < 128 * MiB


def test_storage_is_sized_by_the_format():
    # Per texel / sample: 8-bit unorm colour of one or two channels 1 or 2 bytes, of three or four
    # 4 (RGBA), float and integer colour 16, DEPTH_COMPONENT16/24/32F 4, DEPTH24_STENCIL8 5,
    # STENCIL_INDEX8 1.
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
def delta(make):
    a = softgl._core.memory_in_use(); make(); return softgl._core.memory_in_use() - a
def tex(internal, fmt, typ, w=64, h=32):
    def make():
        t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
        gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, fmt, typ, None)
        globals().setdefault('keep', []).append(t)
    return make
def rb(internal, samples=0, w=64, h=32):
    def make():
        r = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, r)
        gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, internal, w, h)
        globals().setdefault('keep', []).append(r)
    return make
print(delta(tex(gl.R8, gl.RED, gl.UNSIGNED_BYTE)), delta(tex(gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE)),
      delta(tex(gl.RGB8, gl.RGB, gl.UNSIGNED_BYTE)), delta(tex(gl.LUMINANCE, gl.LUMINANCE, gl.UNSIGNED_BYTE)),
      delta(tex(gl.RGBA32F, gl.RGBA, gl.FLOAT)), delta(rb(gl.RGBA8, 4)), delta(rb(gl.DEPTH_COMPONENT16)),
      delta(rb(gl.DEPTH24_STENCIL8)), delta(rb(gl.STENCIL_INDEX8)), gl.getError())
""")
    n = 64 * 32
    # R8 and LUMINANCE: one byte a texel (before: 4, RGBA bytes whatever the channel count), and
    # 3 bytes after the last (Image::kNarrowPad: the sampler's 4-byte reads stay inside).
    assert [int(x) for x in out] == [n + 3, 4 * n, 4 * n, n + 3, 16 * n, 16 * n, 4 * n, 5 * n, n, softgl.NO_ERROR]


# ES 3.0 table 3.13: the bits of each channel (R, G, B, A) of a sized colour format. What a texel
# takes by the spec is their sum / 8 bytes.
TABLE_3_13 = {
    "R32F": (32, 0, 0, 0), "RG32F": (32, 32, 0, 0), "RGB32F": (32, 32, 32, 0), "RGBA32F": (32, 32, 32, 32),
    "R16F": (16, 0, 0, 0), "RG16F": (16, 16, 0, 0), "RGB16F": (16, 16, 16, 0), "RGBA16F": (16, 16, 16, 16),
    "R11F_G11F_B10F": (11, 11, 10, 0), "RGB9_E5": (9, 9, 9, 0), "RGB565": (5, 6, 5, 0), "RGBA4": (4, 4, 4, 4),
    "RGB5_A1": (5, 5, 5, 1), "SRGB8": (8, 8, 8, 0), "SRGB8_ALPHA8": (8, 8, 8, 8), "RGB10_A2": (10, 10, 10, 2),
    "R8_SNORM": (8, 0, 0, 0), "RGBA8_SNORM": (8, 8, 8, 8),
    "R8UI": (8, 0, 0, 0), "R8I": (8, 0, 0, 0), "RG8UI": (8, 8, 0, 0), "RGB8I": (8, 8, 8, 0), "RGBA8UI": (8, 8, 8, 8),
    "R16I": (16, 0, 0, 0), "RG16UI": (16, 16, 0, 0), "RGB16I": (16, 16, 16, 0), "RGBA16UI": (16, 16, 16, 16),
    "R32UI": (32, 0, 0, 0), "RG32I": (32, 32, 0, 0), "RGB32UI": (32, 32, 32, 0), "RGBA32I": (32, 32, 32, 32),
    "RGB10_A2UI": (10, 10, 10, 2),
}
# How each is uploaded (format, type) for texImage2D(..., None).
UPLOAD = {
    1: ("RED", "RED_INTEGER"), 2: ("RG", "RG_INTEGER"), 3: ("RGB", "RGB_INTEGER"), 4: ("RGBA", "RGBA_INTEGER")}


def spec_bytes(name):
    return sum(TABLE_3_13[name]) // 8


def test_float_and_integer_storage_is_sized_by_the_format():
    """docs/reliability.md, "Memory": integer formats store each channel at its own width, so a
    texel takes the table's bytes exactly; float-sampled formats store one float32 per channel of
    their base format (the 32F formats: the table's bytes; the others, e.g. R16F, RGB565, SRGB8,
    4 bytes a channel, kept as float32 so that sampling and blending read them without a
    decode), plus 12 bytes of padding an image with fewer than 4 channels (Image::kColorPad: a
    4-float load at the last texel stays inside). The 16F formats store one binary16 a channel
    (the table's bytes; the sampler's texel loads decode them) plus 6 bytes of padding below 4
    channels (Image::kHalfPad: a 4-half load at the last texel). Before: 16 bytes a texel for
    every one."""
    names = list(TABLE_3_13)
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
keep = []
def delta(internal, w=64, h=32):
    a = softgl._core.memory_in_use()
    t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
    gl.texStorage2D(gl.TEXTURE_2D, 1, getattr(gl, internal), w, h)
    keep.append(t)
    return softgl._core.memory_in_use() - a
print(*[delta(n) for n in %r], gl.getError())
""" % (names,))
    n = 64 * 32
    got = dict(zip(names, map(int, out)))
    assert int(out[-1]) == softgl.NO_ERROR
    for name, bits in TABLE_3_13.items():
        channels = sum(1 for b in bits if b)
        if name.endswith(("UI", "I")):
            want = n * spec_bytes(name)                       # the table's bytes
        elif name.endswith("16F"):
            want = n * spec_bytes(name) + (6 if channels < 4 else 0)   # binary16 per channel
        else:
            want = n * 4 * channels + (12 if channels < 4 else 0)   # float32 per channel
            if name.endswith("32F"):
                assert want - (12 if channels < 4 else 0) == n * spec_bytes(name)
        assert got[name] == want, (name, got[name], want)


# Renderbuffer formats with an encoding (Image::packed): 16F (EXT_color_buffer_float), sRGB and
# the packed unorm formats, by their ES 3.0 table 3.13 bits.
RENDERBUFFER_ENCODED = ["R16F", "RG16F", "RGBA16F", "SRGB8_ALPHA8", "RGB565", "RGBA4", "RGB5_A1", "RGB10_A2"]


def test_renderbuffers_are_stored_at_the_formats_size():
    """docs/reliability.md, "Memory": a renderbuffer is never sampled, so one of a 16F, sRGB or
    packed unorm format keeps its encoding: a sample takes the table's bytes exactly (before:
    4 bytes a channel of the base format, 16 for RGBA4, RGB5_A1, RGB10_A2 and SRGB8_ALPHA8)."""
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
assert gl.getExtension("EXT_color_buffer_float") is not None
keep = []
def delta(internal, samples, w=64, h=32):
    a = softgl._core.memory_in_use()
    r = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, r)
    gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, getattr(gl, internal), w, h)
    keep.append(r)
    return softgl._core.memory_in_use() - a
print(*[delta(n, s) for n in %r for s in (0, 4)], gl.getError())
""" % (RENDERBUFFER_ENCODED,))
    assert int(out[-1]) == softgl.NO_ERROR
    got = iter(map(int, out[:-1]))
    for name in RENDERBUFFER_ENCODED:
        for samples in (1, 4):
            assert next(got) == 64 * 32 * samples * spec_bytes(name), (name, samples)


def test_peak_rss_of_a_multisampled_16f_renderbuffer():
    """renderbufferStorageMultisample(4, RGBA16F, 2048, 2048): 8 bytes a sample, 128 MiB (before:
    16 bytes a sample, 256 MiB)."""
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
assert gl.getExtension("EXT_color_buffer_float") is not None
before = vm_hwm()
r = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, r)
gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, gl.RGBA16F, 2048, 2048)
print(gl.getError(), vm_hwm() - before)
""")
    assert int(out[0]) == softgl.NO_ERROR
    assert abs(int(out[1]) - 2048 * 2048 * 4 * 8) < 8 * MiB, int(out[1]) / MiB


def test_peak_rss_follows_the_format():
    """A 4096 x 4096 texture in a child process: VmHWM grows by what the format stores (RGBA32F
    256 MiB, R32F 64 MiB, R16F 32 MiB, RG16F 64 MiB (as binary16; 64 and 128 MiB as float32);
    before: 256 MiB each)."""
    grow = {}
    for name in ["RGBA32F", "R32F", "R16F", "RG16F", "R8UI"]:
        out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
before = vm_hwm()
t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
gl.texStorage2D(gl.TEXTURE_2D, 1, gl.%s, 4096, 4096)
print(gl.getError(), vm_hwm() - before)
""" % name)
        assert int(out[0]) == softgl.NO_ERROR
        grow[name] = int(out[1])
    texels = 4096 * 4096
    for name, stored in [("RGBA32F", 16), ("R32F", 4), ("R16F", 2), ("RG16F", 4), ("R8UI", 1)]:
        assert abs(grow[name] - texels * stored) < 8 * MiB, (name, grow[name] / MiB)


def test_textures_are_charged_and_over_the_limit_change_nothing():
    # texImage2D, texStorage2D and generateMipmap charge the ledger; one that would pass the
    # limit records OUT_OF_MEMORY and leaves the texture (its image and bytes) as it was.
    out = run_child("""
import numpy as np
gl = softgl.Context(4, 4, antialias=False, version=2)
base = softgl._core.memory_in_use()
softgl._core.set_memory_limit(base + (16 << 20))
t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
pixels = np.arange(16 * 16 * 4, dtype=np.uint8)
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 16, 16, 0, gl.RGBA, gl.UNSIGNED_BYTE, pixels)
a = softgl._core.memory_in_use() - base
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 4096, 4096, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)   # 64 MiB
e1 = gl.getError()
fb = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0)
back = np.zeros(16 * 16 * 4, np.uint8)
gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.UNSIGNED_BYTE, back)
same = bool((back == pixels).all())
gl.bindFramebuffer(gl.FRAMEBUFFER, None)
t2 = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t2)
gl.texStorage2D(gl.TEXTURE_2D, 13, gl.RGBA8, 4096, 4096)
e2 = gl.getError(); b = softgl._core.memory_in_use() - base
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 1024, 1024, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)   # 4 MiB
c = softgl._core.memory_in_use() - base
gl.generateMipmap(gl.TEXTURE_2D)
d = softgl._core.memory_in_use() - base
softgl._core.set_memory_limit(base + c + 1024)
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 2048, 2048, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)   # 16 MiB: over
e3 = gl.getError()
print(a, e1, int(same), e2, b, c, d, e3, softgl._core.memory_in_use() - base, vm_hwm())
""")
    mip = sum(4 * (1024 >> k) ** 2 for k in range(11))
    assert [int(x) for x in out[:9]] == [16 * 16 * 4, softgl.OUT_OF_MEMORY, 1, softgl.OUT_OF_MEMORY, 16 * 16 * 4,
                                         16 * 16 * 4 + 4 * MiB, 16 * 16 * 4 + mip, softgl.OUT_OF_MEMORY,
                                         16 * 16 * 4 + mip]
    assert int(out[9]) < 150 * MiB


def test_drawing_buffers_are_charged():
    # Colour, depth (and stencil) of every sample: 256 x 128 x 4 samples x (4 + 4 + 1) bytes.
    out = run_child("""
a = softgl._core.memory_in_use()
gl = softgl.Context(256, 128, antialias=True, stencil=True)
b = softgl._core.memory_in_use()
gl.canvas.width = 512                                   # resize: the old buffer's bytes go back
c = softgl._core.memory_in_use()
del gl
import gc; gc.collect()
print(b - a, c - a, softgl._core.memory_in_use() - a)
""")
    per = 4 * 9
    assert int(out[0]) == 256 * 128 * per
    assert int(out[1]) == 512 * 128 * per
    assert int(out[2]) == 0


def test_released_storage_is_returned_to_the_ledger():
    out = run_child("""
gl = softgl.Context(4, 4, antialias=False, version=2)
base = softgl._core.memory_in_use()
softgl._core.set_memory_limit(base + (64 << 20))
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, 40 << 20, gl.STATIC_DRAW)
a = softgl._core.memory_in_use() - base
gl.bufferData(gl.ARRAY_BUFFER, 1000, gl.STATIC_DRAW)    # resize: the 40 MiB go back
c = softgl._core.memory_in_use() - base
rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, 1024, 1024)
d = softgl._core.memory_in_use() - base
print(a, c, d, gl.getError())
""")
    assert [int(x) for x in out] == [40 * MiB, 1000, 1000 + 1024 * 1024 * 5, softgl.NO_ERROR]


def rss():
    return "[int(l.split()[1]) * 1024 for l in open('/proc/self/status') if l.startswith('VmRSS:')][0]"


def test_delete_frees_storage_at_once_while_python_holds_the_handle():
    # Finding 12: deleteTexture / deleteRenderbuffer / deleteBuffer with the Python handle alive
    # freed nothing (2,077 MB held). Now each gives its bytes back to the ledger and the process
    # (RSS) at once, the handles still usable as deleted objects.
    out = run_child(f"""
import numpy as np
gl = softgl.Context(4, 4, antialias=False, version=2)
def rss(): return {rss()}
base, rss0 = softgl._core.memory_in_use(), rss()
t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 4096, 4096, 0, gl.RGBA, gl.UNSIGNED_BYTE,
              np.full(4096 * 4096 * 4, 7, np.uint8))                       # 64 MiB, touched
r = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, r)
gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, 4096, 2048)   # 40 MiB
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, np.ones(8 << 20, np.float32), gl.STATIC_DRAW)  # 32 MiB, touched
held, rss1 = softgl._core.memory_in_use() - base, rss()
gl.deleteTexture(t); a = softgl._core.memory_in_use() - base
gl.deleteRenderbuffer(r); c = softgl._core.memory_in_use() - base
gl.deleteBuffer(b); d = softgl._core.memory_in_use() - base
rss2 = rss()
print(held, a, c, d, int(gl.isTexture(t)), gl.getError(), rss1 - rss0, rss2 - rss0)
""")
    held, a, c, d, is_tex, err, grown, left = (int(x) for x in out)
    tex, rb, buf = 64 * MiB, 4096 * 2048 * 5, 32 * MiB
    assert held == tex + rb + buf
    assert (a, c, d) == (rb + buf, buf, 0)
    assert is_tex == 0 and err == softgl.NO_ERROR
    assert grown > 90 * MiB                 # the texture and the buffer were written: resident
    assert left < 8 * MiB                   # and given back


def test_an_object_attached_to_an_unbound_framebuffer_lives_until_detached():
    # ES 3.0 §4.4.2.3: deleting detaches only from the bound framebuffers; an attachment of
    # another framebuffer keeps the image (and its contents) until it is detached or that
    # framebuffer is deleted. A buffer of a vertex array that is not bound likewise (§5.1.3).
    out = run_child("""
import numpy as np
gl = softgl.Context(4, 4, antialias=False, version=2)
base = softgl._core.memory_in_use()
def used(): return softgl._core.memory_in_use() - base
t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 256, 256, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)
fb = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0)
gl.clearColor(0.2, 0.4, 0.6, 0.8); gl.clear(gl.COLOR_BUFFER_BIT)
gl.bindFramebuffer(gl.FRAMEBUFFER, None)
gl.deleteTexture(t); a = used()                           # kept: fb (unbound) holds it
gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
px = gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)
status = gl.checkFramebufferStatus(gl.FRAMEBUFFER)
gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, None, 0)
b = used()                                                # detached: freed
r = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, r)
gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, 128, 128)
gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, r)
gl.bindFramebuffer(gl.FRAMEBUFFER, None)
gl.deleteRenderbuffer(r); c = used()                      # kept by fb
gl.deleteFramebuffer(fb); d = used()                      # fb gone: freed (fb's handle lives on)
vao = gl.createVertexArray(); gl.bindVertexArray(vao)
buf = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf)
gl.bufferData(gl.ARRAY_BUFFER, 1 << 20, gl.STATIC_DRAW)
gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
gl.bindVertexArray(None)
gl.deleteBuffer(buf); e = used()                          # kept by vao
gl.bindVertexArray(vao)
gl.deleteBuffer(buf); f = used()                          # already deleted: nothing more
gl.bindVertexArray(None); gl.deleteVertexArray(vao); g = used()
print(a, *px.ravel(), status, b, c, d, e, f, g, gl.getError())
""")
    v = [int(x) for x in out]
    assert v[0] == 256 * 256 * 4
    assert v[1:5] == [51, 102, 153, 204]
    assert v[5] == softgl.FRAMEBUFFER_COMPLETE
    assert v[6:] == [0, 128 * 128 * 4, 0, 1 << 20, 1 << 20, 0, softgl.NO_ERROR]


def test_each_context_has_its_own_budget_within_the_process_total():
    # A context's budget (gl.set_memory_budget) bounds its own objects; other contexts are not
    # charged for them; the process-wide limit bounds them all. Over either: OUT_OF_MEMORY
    # naming the call, the size and which limit, nothing allocated.
    out = run_child("""
import warnings
gl = softgl.Context(4, 4, antialias=False, version=2)
other = softgl.Context(4, 4, antialias=False, version=2)
messages = []
warnings.showwarning = lambda message, *a, **k: messages.append(str(message))
warnings.simplefilter('always')
gl.set_memory_budget(gl.memory_budget()["in_use"] + (50 << 20))
bufs = []
for ctx in (gl, gl, other, other):
    b = ctx.createBuffer(); ctx.bindBuffer(ctx.ARRAY_BUFFER, b); bufs.append(b)
    ctx.bufferData(ctx.ARRAY_BUFFER, 30 << 20, ctx.STATIC_DRAW)
    print(ctx.getError(), end=' ')
t = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, t)
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 2048, 4096, 0, gl.RGBA, gl.UNSIGNED_BYTE, None)   # 32 MiB: over 50
print(gl.getError(), end=' ')
m = gl.memory_budget()
print(m["in_use"] - 128, other.memory_budget()["in_use"] - 128, m["process_in_use"] - 256, end=' ')
softgl._core.set_memory_limit(m["process_in_use"] + (10 << 20))
gl.set_memory_budget(None)
other.bufferData(other.ARRAY_BUFFER, 40 << 20, other.STATIC_DRAW)   # over the process limit
print(other.getError(), vm_hwm())
print('|'.join(messages))
""")
    first, msgs = out[:10], " ".join(out[10:])
    v = [int(x) for x in first]
    assert v[:5] == [softgl.NO_ERROR, softgl.OUT_OF_MEMORY, softgl.NO_ERROR, softgl.NO_ERROR, softgl.OUT_OF_MEMORY]
    assert v[5:8] == [30 * MiB, 60 * MiB, 90 * MiB]
    assert v[8] == softgl.OUT_OF_MEMORY
    assert v[9] < 90 * MiB + 100 * MiB      # the refused 30 and 40 MiB were never allocated
    assert "bufferData" in msgs and "this context's memory" in msgs and "31457280" in msgs
    assert "texImage2D" in msgs and "33554432" in msgs
    assert "softgl's (all contexts') memory" in msgs


def test_default_context_budget_comes_from_the_machines_memory():
    out = run_child("""
import os
gl = softgl.Context(4, 4, antialias=False)
m = gl.memory_budget()
print(m["limit"], os.sysconf('SC_PHYS_PAGES') * os.sysconf('SC_PAGE_SIZE') // 2, m["in_use"], 4 * 4 * 9)
""")
    v = [int(x) for x in out]
    assert v[0] == v[1]
    assert v[2] == 4 * 4 * 8    # RGBA8 + depth (antialias=False, no stencil)


def test_a_draws_working_memory_is_charged_to_its_context():
    # drawElements' index words and a draw's copies for a rollback (pipeline/draw_rollback.h)
    # count against the context's budget for the call's length: over it, OUT_OF_MEMORY before
    # any pixel is written, the picture unchanged; within it, the draw runs and gives them back.
    out = run_child("""
import numpy as np
# One thread: each worker's scratch grows with the tiles it happened to draw, so at more threads
# what the scratch holds may differ between runs by scheduling.
gl = softgl.Context(256, 256, antialias=False, version=2, threads=1)
vs = "#version 300 es\\nin vec2 p;\\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); gl_PointSize = 1.0; }"
fs = ("#version 300 es\\nprecision highp float;\\nuniform int n;\\nout vec4 o;\\n"
      "void main() { float x = 0.0; for (int i = 0; i < n; i++) x += 0.25; o = vec4(x, 0.0, 0.0, 1.0); }")
prog = softgl.program(gl, vs, fs, {"p": 0}); gl.useProgram(prog)
gl.uniform1i(gl.getUniformLocation(prog, "n"), 2)
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, 1, 1], np.float32), gl.STATIC_DRAW)
gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
e = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, e)
gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.zeros(1 << 20, np.uint8), gl.STATIC_DRAW)   # 2^20 indices
# Both draws once first: the scratch they keep on this thread (charged after each draw) is then
# at its size, and the same draws again grow it no more.
gl.drawElements(gl.POINTS, 1 << 20, gl.UNSIGNED_BYTE, 0); gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4)
gl.clearColor(0.2, 0.2, 0.2, 1.0); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
before = gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE).copy()
in_use = gl.memory_budget()["in_use"]
# The loop's bound is a uniform, so the draw keeps copies: 256 x 256 x (4 + 4) bytes.
gl.set_memory_budget(in_use + 256 * 256 * 8 - 1)
gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4); e1 = gl.getError()
same1 = bool((gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE) == before).all())
gl.set_memory_budget(in_use + (4 << 20) - 1)                         # 2^20 index words need 4 MiB
gl.drawElements(gl.POINTS, 1 << 20, gl.UNSIGNED_BYTE, 0); e2 = gl.getError()
same2 = bool((gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE) == before).all())
gl.set_memory_budget(in_use + (4 << 20) + 256 * 256 * 8)
gl.drawElements(gl.POINTS, 1 << 20, gl.UNSIGNED_BYTE, 0); e3 = gl.getError()
gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4); e4 = gl.getError()
drawn = int(gl.readPixels(128, 128, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0, 0])
print(e1, int(same1), e2, int(same2), e3, e4, drawn, gl.memory_budget()["in_use"] - in_use)
""")
    v = [int(x) for x in out]
    assert v == [softgl.OUT_OF_MEMORY, 1, softgl.OUT_OF_MEMORY, 1, softgl.NO_ERROR, softgl.NO_ERROR, 128, 0]


def test_a_draws_kept_scratch_and_the_blend_labs_records_are_charged():
    """The scratch a draw keeps on its thread (its batch's vertices, set-up primitives and bins,
    every worker's tile-pass buffers, the rollback copies) and the blend lab's A-buffer are
    charged to the context that drew (memory_budget()["in_use"]): what the context holds, checked
    against the growth of the process's resident memory, and the A-buffer against its records'
    own count. Before, neither was charged (in_use did not move)."""
    out = run_child("""
import numpy as np
def rss():
    for line in open('/proc/self/status'):
        if line.startswith('VmRSS:'): return int(line.split()[1]) * 1024
gl = softgl.Context(256, 256, antialias=False, threads=1)
gl.useProgram(softgl.program(gl, "attribute vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }",
                             "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.0, 0.0, 0.25); }"))
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
n = 3 * 200000                                                    # 200,000 triangles: 4 batches
gl.bufferData(gl.ARRAY_BUFFER, np.random.default_rng(1).uniform(-1, 1, (n, 2)).astype(np.float32), gl.STATIC_DRAW)
gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
m0, r0 = gl.memory_budget()["in_use"], rss()
gl.drawArrays(gl.TRIANGLES, 0, n)
m1, r1 = gl.memory_budget()["in_use"], rss()
# The blend lab: 8 blended full-canvas quads, 8 x 256 x 256 fragments kept in the A-buffer.
ext = gl.getExtension("SOFTGL_exact_transparency")
gl.enable(0x1D100)                                               # EXACT_TRANSPARENCY_SOFTGL
gl.enable(gl.BLEND); gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1] * 8, np.float32), gl.STATIC_DRAW)
gl.drawArrays(gl.TRIANGLES, 0, 6 * 8)                          # the scratch of this shape first
gl.clear(gl.COLOR_BUFFER_BIT)
m2 = gl.memory_budget()["in_use"]
gl.drawArrays(gl.TRIANGLES, 0, 6 * 8)
m3 = gl.memory_budget()["in_use"]
mem = ext.memory()
gl.clear(gl.COLOR_BUFFER_BIT)                                   # a full clear frees the records
m4 = gl.memory_budget()["in_use"]
print(m1 - m0, r1 - r0, mem["fragments"], mem["bytes_stored"], m3 - m2, m4 - m2, gl.getError())
""")
    scratch, grown, fragments, stored, lab, after_clear, err = map(int, out)
    assert err == softgl.NO_ERROR
    # The scratch is charged at its capacity: most of what became resident, at most what could
    # be (vectors grow by doubling: twice the used part, plus pages not yet touched). The resident
    # growth also holds what the draw touches first besides its scratch (the library's code and
    # data pages, malloc's arenas), which depends on the build: the same 38.2 MiB charged came
    # with 39.9 MiB of growth in the installed wheel and 46.8 MiB in a development build.
    assert 8 * MiB < scratch
    assert grown * 3 // 4 <= scratch <= 2 * grown + 8 * MiB, (scratch / MiB, grown / MiB)
    assert fragments == 8 * 256 * 256
    assert stored <= lab <= 2 * stored + MiB, (lab, stored)
    assert after_clear < lab // 8, (after_clear, lab)


def test_an_allocation_failure_anywhere_is_out_of_memory_naming_the_call():
    # Under an address-space limit (RLIMIT_AS) an allocation the ledger allowed can still fail:
    # the std::bad_alloc becomes OUT_OF_MEMORY naming the call (one mechanism for every method,
    # cpp/bindings/arguments.h), not a bare MemoryError; the context stays usable.
    out = run_child("""
import resource, warnings, numpy as np
msgs = []
warnings.showwarning = lambda message, *a, **k: msgs.append(str(message))
warnings.simplefilter('always')
gl = softgl.Context(16, 16, antialias=False, version=2)
vs = "#version 300 es\\nin vec2 p;\\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); gl_PointSize = 1.0; }"
fs = "#version 300 es\\nprecision highp float;\\nout vec4 o;\\nvoid main() { o = vec4(1.0); }"
prog = softgl.program(gl, vs, fs, {"p": 0}); gl.useProgram(prog)
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, np.zeros(2, np.float32), gl.STATIC_DRAW)
gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
e = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, e)
gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, 64 << 20, gl.STATIC_DRAW)      # 2^26 zero indices
vm = [int(l.split()[1]) * 1024 for l in open('/proc/self/status') if l.startswith('VmSize:')][0]
resource.setrlimit(resource.RLIMIT_AS, (vm + (96 << 20), resource.RLIM_INFINITY))
try:
    gl.drawElements(gl.POINTS, 64 << 20, gl.UNSIGNED_BYTE, 0)          # 256 MiB of index words
    outcome = 'returned'
except MemoryError:
    outcome = 'MemoryError'
resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
err = gl.getError()
gl.drawArrays(gl.POINTS, 0, 1)
print(outcome, err, gl.getError())
print('|'.join(msgs))
""")
    assert out[:3] == ["returned", str(softgl.OUT_OF_MEMORY), str(softgl.NO_ERROR)], out
    assert "drawElements" in " ".join(out[3:]) and "bad_alloc" in " ".join(out[3:])


def test_a_link_or_compile_that_runs_out_of_memory_changes_nothing():
    """A std::bad_alloc in a call without a catch of its own must leave the state as it was
    (docs/reliability.md, "Memory"). linkProgram prepares the new executable in locals and
    commits by moves; compileShader likewise. The allocation is made to fail by filling the heap's
    free space and limiting the address space to what is mapped (RLIMIT_AS), so the call's first
    new mapping fails. Before: LINK_STATUS went false on OUT_OF_MEMORY while the old executable
    still drew."""
    out = run_child("""
import resource, numpy as np
gl = softgl.Context(16, 16, antialias=False, version=2)
vs = "#version 300 es\\nin vec2 p;\\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); gl_PointSize = 16.0; }"
fs = "#version 300 es\\nprecision highp float;\\nuniform vec4 c;\\nout vec4 o;\\nvoid main() { o = c; }"
prog = softgl.program(gl, vs, fs, {"p": 0}); gl.useProgram(prog)
gl.uniform4f(gl.getUniformLocation(prog, "c"), 0.25, 0.5, 0.75, 1.0)
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, np.zeros(2, np.float32), gl.STATIC_DRAW)
gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
body = "".join("x = x * 0.5 + c * %d.0;\\n" % (i % 7) for i in range(30000))
big = "#version 300 es\\nprecision highp float;\\nuniform vec4 c;\\nout vec4 o;\\nvoid main() { vec4 x = c;\\n" + body + "o = x; }"
f2 = gl.createShader(gl.FRAGMENT_SHADER); gl.shaderSource(f2, big); gl.compileShader(f2)
f3 = gl.createShader(gl.FRAGMENT_SHADER); gl.shaderSource(f3, fs + "x"); gl.compileShader(f3)   # fails: a log
old = [s for s in gl.getAttachedShaders(prog) if gl.getShaderParameter(s, gl.SHADER_TYPE) == gl.FRAGMENT_SHADER][0]
gl.detachShader(prog, old); gl.attachShader(prog, f2)
gl.shaderSource(f3, big)
def state():
    gl.clear(gl.COLOR_BUFFER_BIT); gl.drawArrays(gl.POINTS, 0, 1)
    return (gl.getProgramParameter(prog, gl.LINK_STATUS), gl.getProgramInfoLog(prog), gl.getActiveUniform(prog, 0).name,
            gl.getShaderParameter(f3, gl.COMPILE_STATUS), gl.getShaderInfoLog(f3),
            gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.UNSIGNED_BYTE).tobytes())
def vmsize():
    with open('/proc/self/status') as f:
        return [int(l.split()[1]) * 1024 for l in f if l.startswith('VmSize:')][0]
before = state()
errors = []
for call in (lambda: gl.linkProgram(prog), lambda: gl.compileShader(f3)):
    fill, start = [], vmsize()            # use up the free heap: the call must map new memory
    while vmsize() < start + (8 << 20):
        fill.extend(bytearray(16384) for _ in range(64))
    resource.setrlimit(resource.RLIMIT_AS, (vmsize(), resource.RLIM_INFINITY))
    try:
        call()
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
    errors.append(gl.getError())
    del fill
after = state()
print(*errors, *[int(a == b) for a, b in zip(before, after)], int(before[0]), int(before[3]))
""")
    v = [int(x) for x in out]
    assert v[:2] == [softgl.OUT_OF_MEMORY, softgl.OUT_OF_MEMORY], str(v)
    assert v[2:8] == [1] * 6, v          # status, logs, uniforms, pixels: as before
    assert v[8:] == [1, 0]               # linked before (and still); f3's failed compile kept
