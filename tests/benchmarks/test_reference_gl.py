"""The llvmpipe reference runner (benchmarks/reference_gl.py) draws what the scene says.

Pixels are checked against values computed by hand, so the runner can be trusted as the other
side of softgl's benchmarks and as a second semantic reference. Every renderer lives in a worker
process (LP_NUM_THREADS is per process); the module shares two of them to stay fast.
"""
from __future__ import annotations

import ctypes.util
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))  # the spawned workers inherit sys.path, so they find it too
import reference_gl as ref  # noqa: E402

W = H = 64

if not (ctypes.util.find_library("EGL") and ctypes.util.find_library("GLESv2")):
    pytest.skip("libEGL/libGLESv2 not installed (Debian: libegl1 libgles2 libegl-mesa0 "
                "libgl1-mesa-dri)", allow_module_level=True)


def _process(threads: int, samples: int = 0, size: int = W) -> ref.LlvmpipeProcess:
    try:
        return ref.LlvmpipeProcess(size, size, threads=threads, samples=samples)
    except ref.ReferenceUnavailable as e:
        pytest.skip(f"llvmpipe through EGL unavailable: {e}")


@pytest.fixture(scope="module")
def lp():
    with _process(threads=2) as proc:
        yield proc


VS3 = """#version 300 es
in vec3 aPos;
void main() { gl_Position = vec4(aPos, 1.0); }
"""
FS3 = """#version 300 es
precision mediump float;
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
"""
# GLSL ES 1.00 goes to Mesa unchanged, like 3.00.
VS1 = """attribute vec2 aPos;
void main() { gl_Position = vec4(aPos, 0.0, 1.0); }
"""
FS1 = """precision mediump float;
uniform vec4 uColor;
void main() { gl_FragColor = uColor; }
"""


def quad(x0=-1.0, y0=-1.0, x1=1.0, y1=1.0, z=0.0) -> np.ndarray:
    return np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z],
                     [x0, y0, z], [x1, y1, z], [x0, y1, z]], np.float32)


def test_renderer_is_llvmpipe_es3(lp):
    info = lp.info()
    assert "llvmpipe" in info["renderer"]
    assert info["version"].startswith("OpenGL ES 3.")


def test_fullscreen_constant_color_glsl_es_100_indexed(lp):
    # Four corners + six uint16 indices: drawElements, and an ES 1.00 shader pair.
    scene = ref.Scene(VS1, FS1,
                      attributes={"aPos": np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], np.float32)},
                      indices=np.array([0, 1, 2, 0, 2, 3], np.uint16),
                      uniforms={"uColor": (0.2, 0.4, 0.6, 1.0)})
    img = lp.render(scene)
    assert img.shape == (H, W, 4) and img.dtype == np.uint8
    # unorm8 = round(255 * c): 51, 102, 153, 255
    assert (img == [51, 102, 153, 255]).all()


def test_lower_left_triangle_rows_bottom_up(lp):
    tri = np.array([[-1, -1, 0], [1, -1, 0], [-1, 1, 0]], np.float32)
    scene = ref.Scene(VS3, FS3, attributes={"aPos": tri}, uniforms={"uColor": (1, 1, 1, 1)},
                      state=ref.State(clear_color=(0, 0, 0, 1)))
    img = lp.render(scene)
    # Pixel (x, y) has its centre at (x + .5, y + .5): inside iff x + y < 63; on the edge iff
    # x + y == 63 (the tie rule decides; not checked here). Row 0 of the array is the bottom row.
    y, x = np.mgrid[0:H, 0:W]
    lit = img[..., 0] == 255
    assert lit[x + y < H - 1].all()
    assert not lit[x + y > H - 1].any()
    assert set(np.unique(img[..., 0])) == {0, 255}
    assert lit[0, 0] and not lit[H - 1, W - 1]


def test_alpha_blending_two_quads(lp):
    # Red opaque quad on the left 3/4, then half-transparent blue on the right 3/4, over
    # transparent black, with SRC_ALPHA / ONE_MINUS_SRC_ALPHA for colour and alpha alike.
    pos = np.concatenate([quad(-1, -1, 0.5, 1), quad(-0.5, -1, 1, 1)])
    scene = ref.Scene(VS3, FS3, attributes={"aPos": pos},
                      draws=[ref.Draw(0, 6, {"uColor": (1, 0, 0, 1)}),
                             ref.Draw(6, 6, {"uColor": (0, 0, 1, 0.5)})],
                      state=ref.State(blend=True, blend_func=("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")))
    img = lp.render(scene).astype(int)
    red_only, both, blue_only = img[32, 5], img[32, 32], img[32, 60]
    assert (red_only == [255, 0, 0, 255]).all()
    # 0.5*(0,0,1,0.5) + 0.5*(1,0,0,1) = (0.5, 0, 0.5, 0.75) -> 127.5, 0, 127.5, 191.25
    assert np.abs(both - [127.5, 0, 127.5, 191.25]).max() <= 1
    # 0.5*(0,0,1,0.5) + 0.5*(0,0,0,0) = (0, 0, 0.5, 0.25) -> 0, 0, 127.5, 63.75
    assert np.abs(blue_only - [0, 0, 127.5, 63.75]).max() <= 1


@pytest.mark.parametrize("state, expected", [
    (dict(depth_test=True, depth_func="LESS"), [0, 255, 0, 255]),     # far red quad fails
    (dict(depth_test=False), [255, 0, 0, 255]),                        # no test: last wins
    (dict(depth_test=True, depth_mask=False), [255, 0, 0, 255]),      # near quad left depth 1.0
    (dict(depth_test=True, depth_func="GREATER", clear_depth=0.0), [255, 0, 0, 255]),
])
def test_depth(lp, state, expected):
    # A near green quad (z = -0.5) drawn first, then a far red one (z = +0.5).
    pos = np.concatenate([quad(z=-0.5), quad(z=0.5)])
    scene = ref.Scene(VS3, FS3, attributes={"aPos": pos},
                      draws=[ref.Draw(0, 6, {"uColor": (0, 1, 0, 1)}),
                             ref.Draw(6, 6, {"uColor": (1, 0, 0, 1)})],
                      state=ref.State(**state))
    img = lp.render(scene)
    assert (img == expected).all()


def test_texture_nearest_bottom_row_first(lp):
    vs = """#version 300 es
    in vec2 aPos;
    out vec2 vUV;
    void main() { vUV = aPos * 0.5 + 0.5; gl_Position = vec4(aPos, 0.0, 1.0); }
    """
    fs = """#version 300 es
    precision mediump float;
    uniform sampler2D uTex;
    in vec2 vUV;
    out vec4 fragColor;
    void main() { fragColor = texture(uTex, vUV); }
    """
    texels = np.array([[[255, 0, 0, 255], [0, 255, 0, 255]],      # row 0: bottom
                       [[0, 0, 255, 255], [255, 255, 255, 255]]], np.uint8)
    scene = ref.Scene(vs, fs, attributes={"aPos": quad()[:, :2]},
                      textures={"uTex": ref.Texture(texels, "NEAREST", "NEAREST")})
    img = lp.render(scene)
    assert (img[:32, :32] == texels[0, 0]).all() and (img[:32, 32:] == texels[0, 1]).all()
    assert (img[32:, :32] == texels[1, 0]).all() and (img[32:, 32:] == texels[1, 1]).all()


def test_compile_error_reports_info_log(lp):
    with pytest.raises(ValueError, match="fragment shader does not compile"):
        lp.render(ref.Scene(VS3, FS3.replace("uColor;", "uColor"), attributes={"aPos": quad()}))


def test_time_draws_returns_every_sample(lp):
    times = lp.time_draws(ref.fullscreen_quads(4), repeats=5)
    assert len(times) == 5 and all(0 < t < 5 for t in times)


def test_thread_count_reaches_the_worker(lp):
    # Mesa names its rasterizer threads llvmpipe-<i>: counting them shows what it really started.
    assert lp.info()["threads"] == 2 and lp.info()["raster_threads"] == 2
    with _process(threads=1) as one:
        assert one.info()["threads"] == 1 and one.info()["raster_threads"] == 1


def test_run_in_subprocess_msaa_edges():
    tri = np.array([[-1, -1, 0], [1, -1, 0], [-1, 1, 0]], np.float32)
    scene = ref.Scene(VS3, FS3, attributes={"aPos": tri}, uniforms={"uColor": (1, 1, 1, 1)})
    try:
        out = ref.run_in_subprocess(scene, threads=1, width=W, height=H, samples=4, repeats=2)
    except ref.ReferenceUnavailable as e:
        pytest.skip(f"llvmpipe through EGL unavailable: {e}")
    assert out["raster_threads"] == 1 and out["samples"] == 4 and len(out["times"]) == 2
    red = out["image"][..., 0].astype(int)
    y, x = np.mgrid[0:H, 0:W]
    assert (red[x + y < H - 2] == 255).all() and (red[x + y > H] == 0).all()
    # The resolved diagonal is partly covered: 4 samples give levels between 0 and 255.
    diagonal = red[x + y == H - 1]
    assert ((diagonal > 0) & (diagonal < 255)).all()


def test_second_thread_count_in_one_process_is_refused():
    code = textwrap.dedent(f"""
        import sys; sys.path.insert(0, {str(BENCHMARKS)!r})
        import reference_gl as ref
        ref.LlvmpipeRenderer(8, 8, threads=1).close()
        try:
            ref.LlvmpipeRenderer(8, 8, threads=2)
        except RuntimeError as e:
            print("refused:", e)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    if "ReferenceUnavailable" in out.stderr:
        pytest.skip("llvmpipe through EGL unavailable")
    assert "refused: llvmpipe in this process already runs with LP_NUM_THREADS=1" in out.stdout


def test_memory_bandwidth_is_measured():
    gbs = ref.measure_memory_bandwidth(size_mb=32, repeats=3, threads=2)
    assert 0.1 < gbs < 10_000
