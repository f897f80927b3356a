"""Resources and concurrency: absurd sizes give a clear error and allocate nothing; memory does
not grow across many draw/clear cycles; contexts drawing in several Python threads at once give
the same bytes as one after another. Figures are in docs/reliability.md."""
import os
import subprocess
import sys
import threading
import warnings

import numpy as np
import pytest

import softgl
from stress_helpers import Painter, context, pixels, quiet, rss_bytes

MiB = 1 << 20
HERE = os.path.dirname(__file__)


def run_isolated(code: str, limit_bytes: int = 3 << 30, timeout: float = 120):
    """Runs `code` in a fresh interpreter under RLIMIT_AS (a crash or an OOM kill cannot take
    the test run down; an allocation the limit refuses shows up as bad_alloc/MemoryError)."""
    prelude = (f"import resource, sys; resource.setrlimit(resource.RLIMIT_AS, ({limit_bytes}, {limit_bytes}))\n"
               f"sys.path.insert(0, {HERE!r})\n")
    return subprocess.run([sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=timeout)


# ----------------------------------------------------------------------------- absurd sizes

@pytest.mark.parametrize("size", [(0, 10), (10, -1), (16385, 16), (16, 2**31 - 1), (2**31 - 1, 2**31 - 1)])
def test_absurd_canvas_sizes_raise_before_allocating(size):
    before = rss_bytes()
    with pytest.raises(ValueError, match="softgl.Context|drawing buffer"):
        softgl.Context(*size)
    assert rss_bytes() - before < 8 * MiB


def test_canvas_larger_than_half_the_memory_is_refused():
    # 16384^2 x 16 samples x (color + depth + stencil) = 36 GiB: refused by the memory budget.
    before = rss_bytes()
    pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    if 16384 * 16384 * 16 * 9 <= pages // 2:
        pytest.skip("this machine has room for it")
    with pytest.raises(ValueError, match="memory"):
        softgl.Context(16384, 16384, antialias=True, samples=16, stencil=True)
    assert rss_bytes() - before < 8 * MiB


@pytest.mark.parametrize("size", [2**34 + 1, 2**40, 2**62, 2**63 - 1])
def test_absurd_buffer_sizes_are_out_of_memory_and_allocate_nothing(size):
    gl = context(4, 4)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, 16, gl.STATIC_DRAW)
    before = rss_bytes()
    with quiet():
        gl.bufferData(gl.ARRAY_BUFFER, size, gl.STATIC_DRAW)
    assert gl.getError() == gl.OUT_OF_MEMORY
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 16   # unchanged
    assert rss_bytes() - before < 8 * MiB


def test_buffer_size_beyond_int64_is_a_clear_python_error():
    gl = context(4, 4)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    with pytest.raises((TypeError, OverflowError), match="bufferData"):
        gl.bufferData(gl.ARRAY_BUFFER, 2**64, gl.STATIC_DRAW)


@pytest.mark.parametrize("w,h", [(2**31 - 1, 2**31 - 1), (2**31 - 1, 1), (100000, 100000)])
def test_absurd_read_pixels_is_out_of_memory(w, h):
    # Isolated under a 2 GiB address-space limit: today (2**31-1, 1) zero-fills 8 GiB otherwise.
    r = run_isolated(f"""
import softgl, warnings
from stress_helpers import rss_bytes
warnings.simplefilter('ignore')
gl = softgl.Context(4, 4)
before = rss_bytes()
out = gl.readPixels(0, 0, {w}, {h}, gl.RGBA, gl.UNSIGNED_BYTE)
print(out is None, gl.getError(), (rss_bytes() - before) >> 20)
""", limit_bytes=2 << 30)
    assert r.returncode == 0, r.stderr[-600:]
    returned_none, error, grown_mib = r.stdout.split()[-3:]
    assert returned_none == "True" and int(error) == softgl.OUT_OF_MEMORY and int(grown_mib) < 8


def test_huge_draw_counts_against_small_buffers_fail_fast():
    """Validation catches counts that would read past the buffers before any work is done."""
    gl = context(8, 8)
    p = Painter(gl, uniform_color=True)
    p.draw(gl.TRIANGLES, np.zeros((3, 4), np.float32), color=(1, 1, 1, 1))
    idx = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, idx)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([0, 1, 2], np.uint16), gl.STATIC_DRAW)
    before = rss_bytes()
    with quiet():
        for args in [(gl.TRIANGLES, 0, 2**31 - 1), (gl.TRIANGLES, 2**31 - 1, 2**31 - 1), (gl.POINTS, 3, 1)]:
            gl.drawArrays(*args)
            assert gl.getError() == gl.INVALID_OPERATION, args
        gl.drawElements(gl.TRIANGLES, 2**31 - 1, gl.UNSIGNED_SHORT, 0)
        assert gl.getError() == gl.INVALID_OPERATION
        gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 2**62)
        assert gl.getError() == gl.INVALID_OPERATION
        gl.vertexAttribDivisor(0, 1)
        gl.drawArraysInstanced(gl.TRIANGLES, 0, 3, 2**31 - 1)
        assert gl.getError() == gl.INVALID_OPERATION
    assert rss_bytes() - before < 4 * MiB
    assert gl.stats()["draws"] == 1


def test_huge_draw_needs_no_memory_proportional_to_its_size():
    # 2^27 points: unbatched, their vertex outputs alone (20 bytes each) would exceed the 3 GiB
    # address-space limit; drawn in batches they need a few MiB (pipeline/draw.cpp).
    r = run_isolated("""
import softgl, warnings
warnings.simplefilter('ignore')
gl = softgl.Context(4, 4, antialias=False)
prog = softgl.program(gl, 'void main(){gl_Position=vec4(2.0,2.0,0.0,1.0); gl_PointSize=1.0;}',
                      'precision mediump float; void main(){gl_FragColor=vec4(1.0);}')
gl.useProgram(prog)
gl.drawArrays(gl.POINTS, 0, 2**27)
print('error', gl.getError(), gl.stats()['primitives_outside'])
""", limit_bytes=3 << 30, timeout=300)
    assert r.returncode == 0, r.stderr[-1500:]
    assert r.stdout.split()[-2:] == [str(softgl.NO_ERROR), str(2**27)]


def test_draw_working_memory_is_bounded():
    # Peak RSS (ru_maxrss) around draws of 10^6 and then 4 x 10^6 points, after a small warm-up
    # draw. The first pays for one batch's scratch (~25 MiB: 2^16 set-up points and their
    # vertices), which later draws reuse: the second, four times larger, must not raise the peak.
    r = run_isolated("""
import resource, softgl
gl = softgl.Context(16, 16, antialias=False)
prog = softgl.program(gl, 'void main(){gl_Position=vec4(0.0,0.0,0.0,1.0); gl_PointSize=1.0;}',
                      'precision mediump float; void main(){gl_FragColor=vec4(1.0);}')
gl.useProgram(prog)
gl.drawArrays(gl.POINTS, 0, 1000)
peak = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
before = peak()
gl.drawArrays(gl.POINTS, 0, 1000000)
after_first = peak()
gl.drawArrays(gl.POINTS, 0, 4000000)
print((after_first - before) // 1024, (peak() - after_first) // 1024, gl.stats()['primitives'])
""", limit_bytes=8 << 30)
    assert r.returncode == 0, r.stderr[-1500:]
    first, second, prims = (int(v) for v in r.stdout.split()[-3:])
    assert prims == 5001000
    assert first < 64, f"peak RSS grew {first} MiB for 10^6 points"
    assert second < 8, f"peak RSS grew {second} MiB more for 4 x 10^6 points after 10^6"


# ----------------------------------------------------------------------------- leaks

def test_no_memory_growth_over_10000_draw_clear_cycles():
    gl = context(64, 64)
    p = Painter(gl)
    rng = np.random.default_rng(0)
    pos = rng.uniform(-1, 1, (30, 4)).astype(np.float32)
    pos[:, 3] = 1
    col = rng.random((30, 4)).astype(np.float32)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)

    def cycle(i):
        gl.clear(gl.COLOR_BUFFER_BIT)
        p.draw(gl.TRIANGLES, pos, colors=col)    # bufferData, attribute setup and a draw
        if i % 100 == 0:
            pixels(gl)

    for i in range(500):                          # warm-up: pools, allocator arenas
        cycle(i)
    start = rss_bytes()
    samples = []
    for i in range(10000):
        cycle(i)
        if i % 1000 == 999:
            samples.append(rss_bytes() - start)
    assert gl.stats()["draws"] == 10500
    # 10,000 cycles; each allocates ~1 KB of buffers: a leak of even 100 bytes/cycle shows as 1 MB.
    assert samples[-1] < 1 * MiB, [s // 1024 for s in samples]
    assert max(samples) < 2 * MiB, [s // 1024 for s in samples]


def test_no_growth_creating_and_dropping_objects_and_contexts():
    def churn():
        gl = context(32, 32)
        for _ in range(20):
            p = Painter(gl)
            p.draw(gl.TRIANGLES, np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [0, 1, 0, 1]], np.float32),
                   color=(1, 0, 0, 1))
            gl.deleteBuffer(p.pos_buf)
            gl.deleteProgram(p.prog)
        with quiet():
            gl.bindBuffer(gl.ARRAY_BUFFER, None)
            gl.enable(0xDEAD)                   # an error and its warning
    for _ in range(30):
        churn()
    start = rss_bytes()
    for _ in range(300):
        churn()
    assert rss_bytes() - start < 2 * MiB


# ----------------------------------------------------------------------------- concurrency

def busy_scene(seed, threads=None):
    gl = context(64, 64, threads=threads) if threads else context(64, 64)
    p = Painter(gl)
    rng = np.random.default_rng(seed)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    for _ in range(25):
        pos = rng.uniform(-1.2, 1.2, (300, 4)).astype(np.float32)
        pos[:, 3] = 1
        p.draw(gl.TRIANGLES, pos, colors=rng.random((300, 4)).astype(np.float32))
    return pixels(gl)


@pytest.mark.parametrize("n_threads", [2, 4, 8])
def test_contexts_in_parallel_threads_match_serial_runs(n_threads):
    serial = [busy_scene(s) for s in range(n_threads)]
    out = [None] * n_threads
    barrier = threading.Barrier(n_threads)

    def run(i):
        barrier.wait()
        out[i] = busy_scene(i)
    threads = [threading.Thread(target=run, args=(i,)) for i in range(n_threads)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i in range(n_threads):
        np.testing.assert_array_equal(out[i], serial[i])


def heavy_additive_draw(layers):
    """A 256x256 context set up to draw `layers` full-screen triangles added up (ONE, ONE): a draw
    long enough for another thread to run meanwhile. Returns (gl, painter, vertex count)."""
    gl = context(256, 256)
    p = Painter(gl)
    pos = np.array([[-1, -1, 0, 1], [3, -1, 0, 1], [-1, 3, 0, 1]] * layers, np.float32)
    gl.bindBuffer(gl.ARRAY_BUFFER, p.pos_buf)
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW)
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 4, gl.FLOAT, False, 0, 0)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    return gl, p, len(pos)


def test_draws_release_the_gil():
    """While one thread draws a heavy scene, another runs Python code."""
    gl, _, n = heavy_additive_draw(400)
    ticks = []
    done = threading.Event()

    def ticker():
        while not done.is_set():
            ticks.append(1)
    t = threading.Thread(target=ticker)
    t.start()
    before = len(ticks)
    gl.drawArrays(gl.TRIANGLES, 0, n)             # 26M fragments: tens of milliseconds at least
    during = len(ticks) - before
    done.set()
    t.join()
    assert during > 100


def test_state_calls_during_another_threads_draw_are_refused():
    """A GIL-holding call (clearColor, bindBuffer, bufferData...) from a second thread while a draw
    runs on the same context gets the 'busy' RuntimeError instead of changing state under the draw.
    The second thread's calls do not affect what the draw reads (clear colour, a buffer the draw
    does not use), so the pixels must equal a single-threaded run."""
    def setup():
        gl, p, n = heavy_additive_draw(300)
        p.color((0.002, 0.001, 0.003, 0.004))
        return gl, n

    gl, n = setup()
    gl.drawArrays(gl.TRIANGLES, 0, n)
    expected = gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE)

    gl, n = setup()
    spare = gl.createBuffer()
    refused, accepted = [], []
    done, started = threading.Event(), threading.Event()

    def meddler():
        started.set()
        while not done.is_set():
            try:
                gl.clearColor(0.5, 0.25, 0.125, 1.0)
                gl.bindBuffer(gl.ARRAY_BUFFER, spare)
                gl.bufferData(gl.ARRAY_BUFFER, 16, gl.STATIC_DRAW)
                accepted.append(1)
            except RuntimeError as e:
                assert "busy" in str(e)
                refused.append(1)
    t = threading.Thread(target=meddler)
    t.start()
    started.wait()
    gl.drawArrays(gl.TRIANGLES, 0, n)   # ~60M fragments, released GIL: the meddler runs meanwhile
    done.set()
    t.join()
    assert refused, "no call reached the context while the draw ran"
    assert gl.getError() == gl.NO_ERROR
    np.testing.assert_array_equal(gl.readPixels(0, 0, 256, 256, gl.RGBA, gl.UNSIGNED_BYTE), expected)
    gl.clearColor(0.5, 0.25, 0.125, 1.0)   # outside a draw the same calls go through
    np.testing.assert_allclose(gl.getParameter(gl.COLOR_CLEAR_VALUE), [0.5, 0.25, 0.125, 1.0])


def test_one_context_shared_by_threads_never_crashes():
    code = """
import threading, numpy as np, warnings
from stress_helpers import Painter, context
warnings.simplefilter('ignore')
gl = context(64, 64)
p = Painter(gl)
def hammer(k):
    rng = np.random.default_rng(k)
    for i in range(500):
        pos = rng.uniform(-1.2, 1.2, (300, 4)).astype(np.float32); pos[:, 3] = 1
        try:
            p.draw(gl.TRIANGLES, pos, color=(1, 0, 0, 1))
        except RuntimeError as e:   # busy in another thread: refused (bindings/exclusive.h), not raced
            assert 'busy' in str(e)
ts = [threading.Thread(target=hammer, args=(i,)) for i in range(4)]
[t.start() for t in ts]; [t.join() for t in ts]
print('ok')
"""
    for attempt in range(2):
        try:
            r = run_isolated(code, limit_bytes=8 << 30, timeout=60)
        except subprocess.TimeoutExpired:
            pytest.fail("deadlock: one context shared by 4 threads did not finish in 60 s")
        assert r.returncode == 0 and r.stdout.strip().endswith("ok"), \
            f"attempt {attempt}: exit {r.returncode}: {r.stderr[-500:]}"
