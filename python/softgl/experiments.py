"""Experiments: labelled image grids (matplotlib) and parameter sweeps (local processes or Dask).

    fig = experiments.blend_matrix()          # source factor x blend equation
    fig = experiments.depth_functions()       # the 8 depth functions
    fig = experiments.points_lesson()         # the 8 depth/blend/mask columns of the points lesson
    table = experiments.sweep(render, {"alpha": [0.25, 0.5], "mode": ["sorted", "unsorted"]})

Every picture is drawn with the WebGL API (softgl.scene or the stock programs) and shown as a
browser would show the canvas (softgl.display.canvas_image: composited over a white page).
"""
from __future__ import annotations

import itertools
import os
import warnings

import numpy as np

from . import display, geometry, programs, scene
from . import transforms as T
from .context import Context
from .errors import GLWarning

BLEND_FACTORS = ["ZERO", "ONE", "SRC_COLOR", "ONE_MINUS_SRC_COLOR", "DST_COLOR",
                 "ONE_MINUS_DST_COLOR", "SRC_ALPHA", "ONE_MINUS_SRC_ALPHA", "DST_ALPHA",
                 "ONE_MINUS_DST_ALPHA", "CONSTANT_COLOR", "ONE_MINUS_CONSTANT_COLOR",
                 "CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_ALPHA", "SRC_ALPHA_SATURATE"]
BLEND_EQUATIONS = ["FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT", "MIN", "MAX"]
DEPTH_FUNCTIONS = ["NEVER", "LESS", "EQUAL", "LEQUAL", "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS"]
BLEND_COLOR = (0.2, 0.6, 0.9, 0.5)


# -- Grids ------------------------------------------------------------------------------------------

def _picture(image):
    if image is None:
        return None
    if hasattr(image, "drawingBufferWidth"):
        return display.canvas_image(image, present=False)
    image = np.asarray(image)
    if image.ndim == 3 and image.shape[2] == 4:
        return display.composite(image, premultiplied=False)
    return image


def image_grid(images, row_labels=None, col_labels=None, title=None, cell_inches=1.3,
               notes=None, col_rotation=0):
    """A matplotlib Figure showing `images` (rows of (h, w, 3|4) top-down arrays or contexts;
    None leaves a cell empty) with labels; `notes[r][c]` writes a text into a cell."""
    import matplotlib.pyplot as plt
    rows = [list(r) for r in images]
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    fig, axes = plt.subplots(n_rows, n_cols, squeeze=False,
                             figsize=(cell_inches * n_cols + 1.6, cell_inches * n_rows + 0.8))
    for r in range(n_rows):
        for c in range(n_cols):
            ax = axes[r][c]
            ax.set_xticks([])
            ax.set_yticks([])
            image = _picture(rows[r][c]) if c < len(rows[r]) else None
            if image is not None:
                ax.imshow(image, interpolation="nearest")
            else:
                ax.set_facecolor("#eeeeee")
            if notes is not None and notes[r][c]:
                ax.text(0.5, 0.5, notes[r][c], ha="center", va="center", fontsize=6,
                        transform=ax.transAxes)
            if row_labels is not None and c == 0:
                ax.set_ylabel(row_labels[r], rotation=0, ha="right", va="center", fontsize=7)
            if col_labels is not None and r == 0:
                ax.set_title(col_labels[c], fontsize=7, rotation=col_rotation,
                             ha="left" if col_rotation else "center")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if title:   # leave room for the title above the column labels
        top = 1 - (0.45 + 0.15 * title.count("\n") + (0.9 if col_rotation else 0)) / fig.get_figheight()
        fig.subplots_adjust(top=top)
    return fig


def save_figure(fig, path, dpi=110):
    """Save a figure as PNG and close it (for scripts; in Jupyter the figure shows itself)."""
    import matplotlib.pyplot as plt
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


# -- Blending ---------------------------------------------------------------------------------------

def _colored_quad(x0, y0, x1, y1, colors, z=0.0) -> geometry.Mesh:
    """A rectangle in the z plane with per-corner RGBA colors (bottom-left, bottom-right,
    top-left, top-right)."""
    p = [[x0, y0, z], [x1, y0, z], [x0, y1, z], [x1, y1, z]]
    return geometry.Mesh(p, np.tile([0, 0, 1], (4, 1)), [[0, 0], [1, 0], [0, 1], [1, 1]],
                         [0, 1, 2, 2, 1, 3], np.asarray(colors, np.float32))


def blend_test_scene(source_blend) -> scene.Scene:
    """The destination: six opaque color bars over a transparent top; the source: a band whose
    color runs from orange to cyan left to right and whose alpha rises from 0 to 1 bottom to top,
    drawn with `source_blend` (a Blend or a mode name)."""
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.0), background=(0, 0, 0, 0))
    bars = [(1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 1, 1)]
    for i, rgb in enumerate(bars):
        x0 = -1 + i / 3
        s.add(_colored_quad(x0, -1, x0 + 1 / 3, 0.5, [rgb + (1.0,)] * 4), shading="vertex")
        s.add(_colored_quad(x0, 0.5, x0 + 1 / 3, 1, [rgb + (0.3,)] * 4), shading="vertex")
    s.add(_colored_quad(-1, -0.7, 1, 0.8, [(1, 0.5, 0, 0), (0, 0.8, 1, 0), (1, 0.5, 0, 1),
                                           (0, 0.8, 1, 1)], z=0.5),
          shading="vertex", blend=source_blend)
    return s


def rgb_image(gl) -> np.ndarray:
    """The drawing buffer's RGB as stored (alpha ignored), (h, w, 3) uint8, top row first: what
    blending computed, before any canvas compositing."""
    w, h = gl.drawingBufferWidth, gl.drawingBufferHeight
    return gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE)[::-1, :, :3].copy()


def short_name(enum_name: str) -> str:
    """ONE_MINUS_SRC_ALPHA -> 1-SRC_ALPHA, for grid labels."""
    return enum_name.replace("ONE_MINUS_", "1-").replace("FUNC_", "")


def render_blend(src="SRC_ALPHA", dst="ONE_MINUS_SRC_ALPHA", equation="FUNC_ADD", size=64,
                 version=2):
    """The blend test scene with one blend state, as an RGB image (see rgb_image); None if
    WebGL rejects the combination (e.g. CONSTANT_COLOR with CONSTANT_ALPHA), as the browser
    console would say."""
    gl = Context(size, size, antialias=False, version=version, preserveDrawingBuffer=True)
    blend = scene.Blend(src, dst, equation, color=BLEND_COLOR)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GLWarning)
        blend.apply(gl)
        if gl.getError() != gl.NO_ERROR:
            return None
    blend_test_scene(blend).render(gl)
    return rgb_image(gl)


def blend_matrix(src_factors=None, equations=None, dst_factor="ONE_MINUS_SRC_ALPHA", size=64):
    """Grid of source factor (rows) x blend equation (columns) with a fixed destination factor."""
    src_factors = src_factors or BLEND_FACTORS
    equations = equations or BLEND_EQUATIONS
    images = [[render_blend(s, dst_factor, e, size) for e in equations] for s in src_factors]
    return image_grid(images, [short_name(f) for f in src_factors],
                      [short_name(e) for e in equations],
                      title=f"RGB of blendFunc(src, {short_name(dst_factor)}) x blendEquation\n"
                            f"(blendColor {BLEND_COLOR})")


def blend_factor_matrix(src_factors=None, dst_factors=None, equation="FUNC_ADD", size=48):
    """Grid of source factor (rows) x destination factor (columns) for one equation; cells that
    WebGL rejects say INVALID_OPERATION."""
    src_factors = src_factors or BLEND_FACTORS
    dst_factors = dst_factors or BLEND_FACTORS[:-1]
    images = [[render_blend(s, d, equation, size) for d in dst_factors] for s in src_factors]
    notes = [["INVALID_\nOPERATION" if im is None else "" for im in row] for row in images]
    return image_grid(images, [short_name(f) for f in src_factors],
                      [short_name(f) for f in dst_factors], notes=notes, cell_inches=0.9,
                      title=f"RGB of blendFunc(src, dst) with {short_name(equation)}", col_rotation=60)


def blend_modes(modes=None, size=96):
    """The scene layer's named blend modes on the blend test scene, side by side."""
    modes = modes or [m for m in scene.BLEND_MODES]
    images = []
    for mode in modes:
        gl = Context(size, size, antialias=False, preserveDrawingBuffer=True)
        images.append(rgb_image(blend_test_scene(mode).render(gl)))
    return image_grid([images], None, modes, title="RGB of the scene layer's blend modes",
                      cell_inches=1.6)


# -- Depth ------------------------------------------------------------------------------------------

def render_depth_function(func, size=96, depth_mask=True, clear_depth=1.0):
    """A blue quad tilted in depth (near on the left, far on the right) drawn with LESS, then a
    red square at constant depth (the middle) with depthFunc(func), then a green bar behind
    everything with LESS, which shows what the red square left in the depth buffer."""
    gl = Context(size, size, antialias=False, preserveDrawingBuffer=True)
    prog = programs.constant_color(gl)
    gl.clearColor(0.9, 0.9, 0.9, 1.0)
    gl.clearDepth(clear_depth)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    gl.enable(gl.DEPTH_TEST)
    tilted = np.array([[-0.9, -0.9, -0.8], [0.9, -0.9, 0.8], [-0.9, 0.3, -0.8],
                       [-0.9, 0.3, -0.8], [0.9, -0.9, 0.8], [0.9, 0.3, 0.8]], np.float32)
    square = np.array([[-0.6, -0.6, 0], [0.6, -0.6, 0], [-0.6, 0.9, 0],
                       [-0.6, 0.9, 0], [0.6, -0.6, 0], [0.6, 0.9, 0]], np.float32)
    bar = np.array([[-1, 0.45, 0.9], [1, 0.45, 0.9], [-1, 0.75, 0.9],
                    [-1, 0.75, 0.9], [1, 0.45, 0.9], [1, 0.75, 0.9]], np.float32)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    loc = prog.attributes["aPosition"]
    gl.enableVertexAttribArray(loc)

    def draw(vertices, color):
        gl.bufferData(gl.ARRAY_BUFFER, vertices, gl.STATIC_DRAW)
        gl.vertexAttribPointer(loc, 3, gl.FLOAT, False, 0, 0)
        prog.set(uMaterialDiffuse=color)
        gl.drawArrays(gl.TRIANGLES, 0, 6)

    gl.depthFunc(gl.LESS)
    draw(tilted, (0.2, 0.3, 0.9, 1.0))
    gl.depthFunc(getattr(gl, func))
    gl.depthMask(depth_mask)
    draw(square, (0.9, 0.2, 0.2, 1.0))
    gl.depthMask(True)
    gl.depthFunc(gl.LESS)
    draw(bar, (0.2, 0.7, 0.3, 1.0))
    return gl


def depth_functions(size=96, depth_mask=True, clear_depth=1.0):
    """The 8 depth functions side by side (see render_depth_function)."""
    images = [render_depth_function(f, size, depth_mask, clear_depth) for f in DEPTH_FUNCTIONS]
    return image_grid([images], None, DEPTH_FUNCTIONS, cell_inches=1.4,
                      title=f"depthFunc(f) for the red square (depthMask {depth_mask}, "
                            f"clearDepth {clear_depth})")


# -- The points lesson ------------------------------------------------------------------------------

# The 8 columns: (label, depth test, blending, blendFunc kind, alpha written, depth written).
# "separate" is blendFuncSeparate(SRC_ALPHA, ONE_MINUS_SRC_ALPHA, ZERO, ONE); "no A" is
# colorMask(true, true, true, false); "no Z" is depthMask(false).
POINTS_COLUMNS = [
    ("1\n-\n-", False, False, None, True, True),
    ("2\ndepth\n-", True, False, None, True, True),
    ("3\n-\nblend", False, True, "combined", True, True),
    ("4\ndepth\nseparate", True, True, "separate", True, True),   # the lesson's standard settings
    ("5\n-\nseparate", False, True, "separate", True, True),
    ("6\n-\nblend\nno A", False, True, "combined", False, True),
    ("7\ndepth\nblend\nno A", True, True, "combined", False, True),
    ("8\ndepth\nblend\nno A, Z", True, True, "combined", False, False),
]


def points_lesson(width=428, height=240, show=True):
    """The points lesson: red, yellow and blue points drawn in that order (red nearest, blue
    farthest) with alpha 1, 0.75, 0.5, 0.25 (rows), under the 8 settings of POINTS_COLUMNS,
    each over a white stripe; the canvas (alpha: true) is composited over a white page, so
    columns that lower the canvas alpha let the page show through. Returns a Figure
    (show=True) or the context."""
    gl = Context(width, height, antialias=False, preserveDrawingBuffer=True)
    prog = programs.constant_color(gl)
    k = width / 854            # the lesson's layout, scaled
    prog.set(uPointSize=60 * k)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.zeros(3, np.float32), gl.STATIC_DRAW)
    loc = prog.attributes["aPosition"]
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, False, 0, 0)
    gl.viewport(0, 0, width, height)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)

    def point(x, y, depth, color, alpha):
        ndc = (2 * x / width - 1, 2 * y / height - 1, 2 * depth - 1)
        prog.set(uModel=T.translate(*ndc), uMaterialDiffuse=color + (alpha,))
        gl.drawArrays(gl.POINTS, 0, 1)

    for i, (_, depth, blend, kind, alpha_write, depth_write) in enumerate(POINTS_COLUMNS):
        x0 = (60 + 100 * i) * k
        (gl.enable if depth else gl.disable)(gl.DEPTH_TEST)
        gl.depthFunc(gl.LESS)
        (gl.enable if blend else gl.disable)(gl.BLEND)
        if kind == "combined":
            gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        elif kind == "separate":
            gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ZERO, gl.ONE)
        gl.depthMask(depth_write)
        # The white stripe: a scissored clear, with the color mask of the column.
        gl.colorMask(True, True, True, alpha_write)
        gl.enable(gl.SCISSOR_TEST)
        gl.scissor(round(x0 + 5 * k), 0, round(20 * k), height)
        gl.clearColor(1, 1, 1, 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.disable(gl.SCISSOR_TEST)
        for row, alpha in enumerate((1.0, 0.75, 0.5, 0.25)):
            y0 = (400 - 100 * row) * height / 480
            point(x0, y0, 0.5, (1.0, 0.0, 0.0), alpha)
            point(x0 + 15 * k, y0 - 15 * k, 0.6, (1.0, 1.0, 0.0), alpha)
            point(x0 + 30 * k, y0 - 30 * k, 0.7, (0.0, 0.0, 1.0), alpha)
    gl.colorMask(True, True, True, True)
    gl.depthMask(True)
    if not show:
        return gl
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.imshow(display.canvas_image(gl, present=False), interpolation="nearest")
    ax.set_xticks([(60 + 100 * i + 30) * k for i in range(8)])
    ax.set_xticklabels([c[0] for c in POINTS_COLUMNS], fontsize=7)
    ax.set_yticks([(480 - 400 + 100 * r + 15) * height / 480 for r in range(4)])
    ax.set_yticklabels(["alpha 1", "0.75", "0.5", "0.25"], fontsize=7)
    ax.set_title("The points lesson: depth test, blending, masks\n"
                 "(red nearest and drawn first, blue farthest and drawn last)", fontsize=10)
    fig.tight_layout()
    return fig


# -- Sweeps -----------------------------------------------------------------------------------------

def _grid_points(grid) -> list[dict]:
    if isinstance(grid, dict):
        names = list(grid)
        return [dict(zip(names, values)) for values in itertools.product(*grid.values())]
    return [dict(p) for p in grid]


def _as_row(result) -> dict:
    return dict(result) if isinstance(result, dict) else {"result": result}


def _call_pickled(payload: bytes, params: dict):
    import cloudpickle
    return cloudpickle.loads(payload)(**params)


def sweep(fn, grid, client=None, processes: int | None = None, progress: bool = True):
    """Run ``fn(**params)`` for every point of `grid` and return a tidy pandas DataFrame: one row
    per point, the parameters as columns, then the result's keys (a dict result) or a ``result``
    column.

    `grid` is a dict of name -> values (every combination, in order) or a list of dicts.
    With a Dask ``distributed.Client`` the calls run on its cluster; otherwise in `processes`
    local worker processes (default: one per core; 0 runs them here, one after another).
    `fn` may be a lambda or a function defined in a notebook (it travels with cloudpickle).
    A tqdm progress bar shows the calls as they finish.
    """
    import pandas as pd
    from tqdm.auto import tqdm

    points = _grid_points(grid)
    results = [None] * len(points)
    bar = tqdm(total=len(points), disable=not progress, desc="sweep")
    if client is not None:
        from distributed import as_completed
        futures = {client.submit(fn, pure=False, **p): i for i, p in enumerate(points)}
        for future in as_completed(futures):
            results[futures[future]] = future.result()
            bar.update()
    elif processes == 0 or len(points) <= 1:
        for i, p in enumerate(points):
            results[i] = fn(**p)
            bar.update()
    else:
        import cloudpickle
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed as done
        payload = cloudpickle.dumps(fn)
        workers = min(processes or os.cpu_count() or 1, len(points))
        # spawn: a fresh interpreter per worker, safe with the drawing threads of this one.
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = {pool.submit(_call_pickled, payload, p): i for i, p in enumerate(points)}
            for future in done(futures):
                results[futures[future]] = future.result()
                bar.update()
    bar.close()
    return pd.DataFrame([{**p, **_as_row(r)} for p, r in zip(points, results)])


# -- Fog --------------------------------------------------------------------------------------------

FOG_MODES = ["LINEAR", "EXP", "EXP2"]


def fog_test_scene(fog: "scene.Fog | None", background=(0.75, 0.78, 0.82, 1.0)) -> scene.Scene:
    """A row of lit cubes receding along a ground plane (eye depths about 3 to 22), for fog."""
    s = scene.Scene(camera=scene.Camera(eye=(0, 1.6, 4), target=(0, 0.4, -6), fovy=50),
                    background=background, fog=fog)
    s.lights = [scene.Light((4, 8, 6), (1, 1, 1))]
    s.ambient = (0.3, 0.3, 0.3)
    s.add(geometry.plane(12, 40, 1, 1), color=(0.35, 0.55, 0.3), model=T.translate(0, 0, -14))
    colors = [(0.9, 0.2, 0.2), (0.95, 0.75, 0.1), (0.2, 0.5, 0.95)]
    for i in range(8):
        x = -1.6 if i % 2 == 0 else 1.6
        s.add(geometry.cube(1.2), color=colors[i % 3],
              model=T.translate(x, 0.6, 1.0 - 2.6 * i) @ T.rotate(0.4 * i, (0, 1, 0)))
    return s


def render_fog(mode=None, density=0.1, start=1.0, end=20.0, size=(160, 100), color=None):
    """The fog test scene with SOFTGL_fog (mode None: no fog), as a context."""
    background = (0.75, 0.78, 0.82, 1.0)
    fog = None if mode is None else scene.Fog(mode, density, start, end,
                                              color=color or background[:3])
    gl = Context(*size, antialias=False, preserveDrawingBuffer=True)
    return fog_test_scene(fog, background).render(gl)


def fog_modes(densities=(0.04, 0.08, 0.16), ends=(30.0, 20.0, 10.0), size=(160, 100)):
    """Grid of fog mode (rows) x density (columns); LINEAR's columns use fog end `ends` (start 1)."""
    images, notes = [], []
    for mode in FOG_MODES:
        if mode == "LINEAR":
            images.append([render_fog(mode, start=1.0, end=e, size=size) for e in ends])
        else:
            images.append([render_fog(mode, density=d, size=size) for d in densities])
    cols = [f"density {d}\n(LINEAR: end {e:g})" for d, e in zip(densities, ends)]
    return image_grid(images, FOG_MODES, cols, cell_inches=2.0,
                      title="SOFTGL_fog: mode x density (fog color = background)")


# -- Antialiasing ----------------------------------------------------------------------------------

AA_METHODS = ["aliased", "smooth (exact area)", "smooth FASTEST", "MSAA 2", "MSAA 4", "MSAA 16"]


def aa_test_triangles(width: int, height: int) -> np.ndarray:
    """Disjoint thin triangles at many slopes (NDC, (n, 3, 2)), a fan of slivers around a centre."""
    tris = []
    n = 12
    for i in range(n):
        a0 = 2 * np.pi * i / n + 0.05
        a1 = a0 + 2 * np.pi / n * 0.45
        r0, r1 = 0.12, 0.95
        p = [(r0 * np.cos(a0), r0 * np.sin(a0)), (r1 * np.cos(a0), r1 * np.sin(a0)),
             (r1 * np.cos(a1), r1 * np.sin(a1))]
        tris.append(p)
    return np.array(tris, np.float64)


def _aa_program(gl):
    prog = programs.constant_color(gl)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    loc = prog.attributes["aPosition"]
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    return prog


def render_coverage(method: str, triangles=None, width=64, height=64) -> np.ndarray:
    """White triangles on black with an antialiasing method; the red channel / 255 as float64
    (h, w), top row first: the covered fraction each method estimates."""
    if method not in AA_METHODS:
        raise ValueError(f"method is one of {AA_METHODS}")
    samples = int(method.split()[1]) if method.startswith("MSAA") else 0
    attrs = dict(samples=samples) if samples else dict(antialias=False)
    gl = Context(width, height, preserveDrawingBuffer=True, **attrs)
    tris = aa_test_triangles(width, height) if triangles is None else np.asarray(triangles)
    prog = _aa_program(gl)
    gl.clearColor(0, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    if method.startswith("smooth"):
        ext = gl.getExtension("SOFTGL_smooth")
        gl.enable(ext.POLYGON_SMOOTH)
        gl.hint(ext.POLYGON_SMOOTH_HINT, gl.FASTEST if "FASTEST" in method else gl.NICEST)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
    prog.set(uMaterialDiffuse=(1, 1, 1, 1))
    gl.bufferData(gl.ARRAY_BUFFER, tris.astype(np.float32).ravel(), gl.STATIC_DRAW)
    gl.drawArrays(gl.TRIANGLES, 0, 3 * len(tris))
    img = gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE)
    return img[::-1, :, 0].astype(np.float64) / 255


def coverage_reference(triangles, width, height, n: int = 32) -> np.ndarray:
    """Covered fraction of every pixel by disjoint triangles (NDC), estimated in NumPy with an
    n x n grid of samples per pixel (error below about 2 / n on an edge pixel), float64 (h, w),
    top row first. Vertices are snapped to 1/256 pixel as the rasterizer does."""
    tris = np.asarray(triangles, np.float64)
    win = np.empty_like(tris)
    win[..., 0] = np.round((tris[..., 0] + 1) * width / 2 * 256) / 256
    win[..., 1] = np.round((tris[..., 1] + 1) * height / 2 * 256) / 256
    offsets = (np.arange(n) + 0.5) / n
    cover = np.zeros((height, width))
    for row in range(height):            # one row of pixels at a time keeps memory small
        sy = row + offsets                                    # (n,)
        sx = (np.arange(width)[:, None] + offsets[None, :]).ravel()   # (w n,)
        X, Y = np.meshgrid(sx, sy)                           # (n, w n)
        inside = np.zeros(X.shape, bool)
        for (x0, y0), (x1, y1), (x2, y2) in win:
            area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            s = np.sign(area)
            e0 = ((x1 - x0) * (Y - y0) - (y1 - y0) * (X - x0)) * s
            e1 = ((x2 - x1) * (Y - y1) - (y2 - y1) * (X - x1)) * s
            e2 = ((x0 - x2) * (Y - y2) - (y0 - y2) * (X - x2)) * s
            inside |= (e0 >= 0) & (e1 >= 0) & (e2 >= 0)
        cover[height - 1 - row] = inside.reshape(n, width, n).mean(axis=(0, 2))
    return cover


def antialiasing_methods(width=64, height=64, crop=(slice(4, 28), slice(36, 60)), zoom=6,
                         methods=None, repeat=3):
    """For each method: a zoomed crop of its coverage image and its error map against the exact
    area coverage ("smooth (exact area)", itself checked against coverage_reference).
    Returns (figure, table) where the table (pandas) has the RMS and max error and the run time."""
    import time
    import pandas as pd
    methods = methods or AA_METHODS
    exact = render_coverage("smooth (exact area)", width=width, height=height)
    crops, errors, rows = [], [], []
    for m in methods:
        times = []
        for _ in range(repeat):
            t = time.perf_counter()
            img = render_coverage(m, width=width, height=height)
            times.append(time.perf_counter() - t)
        err = img - exact
        crops.append(_zoom(img[crop], zoom))
        errors.append(_zoom(_error_colors(err[crop]), zoom))
        rows.append(dict(method=m, rms_error=float(np.sqrt(np.mean(err ** 2))),
                         max_error=float(np.abs(err).max()), seconds=float(min(times))))
    fig = image_grid([crops, errors], ["coverage", "error\n(red +, blue -)"], methods,
                     cell_inches=1.7, title="Antialiasing: zoomed crops and error against the exact area")
    return fig, pd.DataFrame(rows)


def _zoom(image, k):
    image = np.asarray(image)
    if image.ndim == 2:
        image = np.repeat(np.clip(image, 0, 1)[..., None], 3, 2)
        image = np.floor(image * 255 + 0.5).astype(np.uint8)
    return np.repeat(np.repeat(image, k, 0), k, 1)


def _error_colors(err, scale=0.5):
    """Signed error as white (0), red (coverage too high) and blue (too low); full color at
    |err| = scale."""
    e = np.clip(np.asarray(err) / scale, -1, 1)
    rgb = np.ones(e.shape + (3,))
    rgb[..., 1] -= np.abs(e)
    rgb[..., 2] -= np.clip(e, 0, 1)
    rgb[..., 0] -= np.clip(-e, 0, 1)
    return np.floor(rgb * 255 + 0.5).astype(np.uint8)
