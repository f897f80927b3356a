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
    # Per texel / sample: 8-bit unorm colour 4 bytes (RGBA, whatever the channel count), float
    # and integer colour 16, DEPTH_COMPONENT16/24/32F 4, DEPTH24_STENCIL8 5, STENCIL_INDEX8 1.
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
    assert [int(x) for x in out] == [4 * n, 4 * n, 4 * n, 4 * n, 16 * n, 16 * n, 4 * n, 5 * n, n, softgl.NO_ERROR]


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
