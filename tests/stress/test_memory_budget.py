"""Memory accounting across objects (docs/reliability.md, "Memory"): the limit bounds the sum of
all buffers and renderbuffers, not each call alone; going over records OUT_OF_MEMORY, warns and
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
softgl._core.set_memory_limit(300 << 20)
gl = softgl.Context(4, 4, antialias=False)
errors = []
for i in range(6):
    b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
    gl.bufferData(gl.ARRAY_BUFFER, 100 << 20, gl.STATIC_DRAW)
    errors.append(gl.getError())
    globals()['keep%d' % i] = b
print(*errors, softgl._core.memory_in_use(), vm_hwm())
""")
    errors = [int(e) for e in out[:6]]
    assert errors == [softgl.NO_ERROR] * 3 + [softgl.OUT_OF_MEMORY] * 3
    assert int(out[6]) == 300 * MiB
    assert int(out[7]) < 300 * MiB + 150 * MiB


def test_big_multisample_renderbuffer_is_out_of_memory_not_allocated():
    # 4096 x 4096 x 4 samples of RGBA8 is 256 MiB in softgl's 16-byte samples: over a 128 MiB limit.
    out = run_child("""
softgl._core.set_memory_limit(128 << 20)
gl = softgl.Context(4, 4, antialias=False, version=2)
rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
gl.renderbufferStorageMultisample(gl.RENDERBUFFER, 4, gl.RGBA8, 4096, 4096)
e = gl.getError()
w = gl.getRenderbufferParameter(gl.RENDERBUFFER, gl.RENDERBUFFER_WIDTH)
print(e, w, softgl._core.memory_in_use(), vm_hwm())
""")
    assert int(out[0]) == softgl.OUT_OF_MEMORY
    assert int(out[1]) == 0                      # nothing changed
    assert int(out[2]) == 0
    assert int(out[3]) < 128 * MiB


def test_released_storage_is_returned_to_the_ledger():
    out = run_child("""
softgl._core.set_memory_limit(64 << 20)
gl = softgl.Context(4, 4, antialias=False, version=2)
b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b)
gl.bufferData(gl.ARRAY_BUFFER, 40 << 20, gl.STATIC_DRAW)
a = softgl._core.memory_in_use()
gl.bufferData(gl.ARRAY_BUFFER, 1000, gl.STATIC_DRAW)    # resize: the 40 MiB go back
c = softgl._core.memory_in_use()
rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, 1024, 1024)
d = softgl._core.memory_in_use()
print(a, c, d, gl.getError())
""")
    assert [int(x) for x in out] == [40 * MiB, 1000, 1000 + 1024 * 1024 * 5, softgl.NO_ERROR]
