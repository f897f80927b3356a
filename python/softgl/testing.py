"""Image assertions for tests: per-channel tolerance, outlier count and PSNR, with the images
written to disk when a comparison fails; and ``tuned`` / ``default_tuned``, which switch softgl's
speed paths (core/tuning.h) for a block, to A/B a path.

Errors are in normalized units: a uint8 value v means v/255, uint16 v/65535, floats as they are.
So ``atol=1/255`` allows one 8-bit step, and a uint8 image can be compared with a float64
reference computed by formula. The per-channel statistics come from OpenImageIO's
``ImageBufAlgo.compare``.
"""
from __future__ import annotations

import math
import os
import re
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# OpenImageIO compares in float32: a difference of exactly one 8-bit step can come out a few
# ulps above 1/255. This slack (far below one 16-bit step, 1.5e-5) keeps atol=k/255 meaning
# "k steps are fine".
_SLACK = 1e-6


@dataclass
class ImageComparison:
    """Statistics of actual - expected over all pixels and channels (normalized units)."""
    shape: tuple
    max_error: float
    max_location: tuple      # (row, column, channel) of the largest error
    mean_error: float
    rms_error: float
    psnr: float              # 20 log10(1 / rms) in dB, peak 1.0; inf for identical images
    outliers: int            # pixels with some channel off by more than atol (or non-finite)
    atol: float

    def summary(self) -> str:
        row, col, ch = self.max_location
        return (f"{self.outliers} of {self.shape[0] * self.shape[1]} pixels off by more than "
                f"atol={self.atol:.6g} ({self.atol * 255:.3g}/255); "
                f"max error {self.max_error:.6g} ({self.max_error * 255:.3g}/255) at row {row}, "
                f"column {col}, channel {ch}; mean error {self.mean_error:.3g}; "
                f"PSNR {self.psnr:.2f} dB")


def _image(x, what: str) -> np.ndarray:
    """An (h, w, c) array from an array or a softgl context (its canvas, top row first)."""
    if hasattr(x, "drawingBufferWidth"):
        x = x.readPixels(0, 0, x.drawingBufferWidth, x.drawingBufferHeight,
                         x.RGBA, x.UNSIGNED_BYTE)[::-1]
    a = np.asarray(x)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or 0 in a.shape:
        raise ValueError(f"{what}: expected a non-empty (h, w[, channels]) image, got shape {a.shape}")
    if a.dtype == np.float64:
        a = a.astype(np.float32)
    if a.dtype not in (np.uint8, np.uint16, np.float16, np.float32):
        raise TypeError(f"{what}: images are uint8, uint16 or float arrays, got {a.dtype}")
    return np.ascontiguousarray(a)


def _normalized(a: np.ndarray) -> np.ndarray:
    if a.dtype.kind == "u":
        return a / float(np.iinfo(a.dtype).max)
    return a.astype(np.float64)


def compare_images(actual, expected, atol: float = 1 / 255) -> ImageComparison:
    """Compare two images of the same shape; see the module docstring for units."""
    import OpenImageIO as oiio
    a, b = _image(actual, "actual"), _image(expected, "expected")
    if a.shape != b.shape:
        raise ValueError(f"shape mismatch: actual {a.shape} vs expected {b.shape}")
    # OpenImageIO ignores NaN and inf (it reports them as passing), so non-finite values are
    # judged here: equal non-finite values match, anything else is an error of infinite size.
    bad = np.zeros(a.shape, bool)
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        fa, fb = _normalized(a), _normalized(b)
        nonfinite = ~np.isfinite(fa) | ~np.isfinite(fb)
        bad = nonfinite & ~((fa == fb) | (np.isnan(fa) & np.isnan(fb)))
        a, b = np.where(nonfinite, 0, a), np.where(nonfinite, 0, b)
    threshold = atol + _SLACK
    r = oiio.ImageBufAlgo.compare(oiio.ImageBuf(a), oiio.ImageBuf(b), threshold, threshold)
    max_error, where = float(r.maxerror), (int(r.maxy), int(r.maxx), int(r.maxc))
    mean, rms, outliers = float(r.meanerror), float(r.rms_error), int(r.nfail)
    if bad.any():
        err = np.abs(_normalized(a) - _normalized(b))
        outliers = int(((err > threshold) | bad).any(axis=2).sum())
        max_error = mean = rms = math.inf
        where = tuple(int(i) for i in np.argwhere(bad)[0])
    psnr = math.inf if rms == 0 else -math.inf if rms == math.inf else 20 * math.log10(1 / rms)
    return ImageComparison(a.shape, max_error, where, mean, rms, psnr, outliers, atol)


def _for_png(a: np.ndarray) -> np.ndarray:
    """uint8/uint16 as they are; floats clamped and rounded to 8 bits."""
    if a.dtype in (np.uint8, np.uint16):
        return a
    return np.round(np.clip(np.nan_to_num(a.astype(np.float64)), 0, 1) * 255).astype(np.uint8)


def _diff_image(a: np.ndarray, b: np.ndarray, atol: float) -> np.ndarray:
    """RGB, for people: each pixel's largest channel error in gray, scaled so the largest error
    within tolerance is white (small errors become visible); pixels beyond atol in red."""
    err = np.abs(np.nan_to_num(_normalized(a) - _normalized(b), nan=np.inf)).max(axis=2)
    over = err > atol + _SLACK
    within = np.where(over, 0, err)
    gray = within / within.max() if within.max() > 0 else within
    rgb = np.repeat(gray[..., None], 3, axis=2)
    rgb[over] = (1.0, 0.0, 0.0)
    return np.round(rgb * 255).astype(np.uint8)


def _default_name() -> str:
    # pytest sets PYTEST_CURRENT_TEST to "path::test_name[params] (call)".
    current = os.environ.get("PYTEST_CURRENT_TEST", "")
    return current.split("::")[-1].split(" ")[0] or "image"


def _folder_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_.") or "image"


def write_failure_images(folder, actual, expected, atol: float = 1 / 255) -> Path:
    """Write actual.png, expected.png and (for equal shapes) diff.png into `folder`."""
    from .io import save
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    save(_for_png(actual), folder / "actual.png")
    save(_for_png(expected), folder / "expected.png")
    if actual.shape == expected.shape:
        save(_diff_image(actual, expected, atol), folder / "diff.png")
    return folder.resolve()


def assert_images_close(actual, expected, *, atol: float = 1 / 255, max_outliers: int = 0,
                        min_psnr: float | None = None, name: str | None = None,
                        out_dir=None) -> ImageComparison:
    """Assert that two images agree; return the statistics.

    Images are (h, w[, c]) arrays (uint8, uint16 or float; rows in whatever order both use) or
    softgl contexts (their canvas, top row first). They agree when the shapes are equal, at most
    `max_outliers` pixels have a channel off by more than `atol` (normalized units, default one
    8-bit step) and, if `min_psnr` is given, the PSNR in dB is at least that.

    On failure, if `out_dir` is given (e.g. pytest's ``tmp_path``), actual.png, expected.png
    and diff.png (gray = error, amplified; red = beyond atol) are written into
    `out_dir/<name>/` (name defaults to the running pytest test) and the AssertionError names
    the folder; without `out_dir` nothing is written (never into the current directory). The PNGs show row 0 at the top: flip readPixels
    results (``[::-1]``) or pass the context to see them upright; "row" in the message is the
    array's row, i.e. GL's y for readPixels results.
    """
    a, b = _image(actual, "actual"), _image(expected, "expected")
    label = f"images {name!r}" if name else "images"

    def written(*atol_):
        if out_dir is None:
            return "no images written (pass out_dir=, e.g. pytest's tmp_path, to see them)"
        folder = Path(out_dir) / _folder_name(name or _default_name())
        return f"images written to {write_failure_images(folder, a, b, *atol_)}"

    if a.shape != b.shape:
        raise AssertionError(f"{label} differ in shape: actual {a.shape} vs expected {b.shape}; "
                             f"{written()}")
    stats = compare_images(a, b, atol)
    problems = []
    if stats.outliers > max_outliers:
        problems.append(f"{stats.outliers} pixels beyond atol, more than max_outliers={max_outliers}")
    if min_psnr is not None and not stats.psnr >= min_psnr:
        problems.append(f"PSNR {stats.psnr:.2f} dB below min_psnr={min_psnr} dB")
    if problems:
        at = stats.max_location
        raise AssertionError(f"{label} differ: {'; '.join(problems)}.\n  {stats.summary()} "
                             f"(actual {a[at].item()!r}, expected {b[at].item()!r})\n"
                             f"  {written(atol)}")
    return stats


@contextmanager
def tuned(gl, **fields):
    """Within the block, ``gl`` draws with these speed-path switches (fields of core/tuning.h:
    simd, batch_primitives, hidden_surface_removal, depth_bounds, fragment_copies, sampler_path,
    fragment_batches, skip_helper_lanes, hoist_uniform_values, blit_rows, pool_spin_microseconds,
    texture_copies, texel_words, linear_words, lod_free_helper_lanes, depth_blocks, blend_in_place; see softgl._core.testing.set_tuning); afterwards its previous switches are back. Yields the
    context's switches as they were."""
    from softgl import _core
    previous = _core.testing.set_tuning(gl, **fields)
    try:
        yield previous
    finally:
        _core.testing.set_tuning(gl, **previous)


@contextmanager
def default_tuned(**fields):
    """Within the block, contexts created get these speed-path switches (as ``tuned``; for code
    that makes its own contexts, e.g. the benchmark scenes); afterwards the previous defaults are
    back. Contexts made within the block keep theirs."""
    from softgl import _core
    previous = _core.testing.set_default_tuning(**fields)
    try:
        yield previous
    finally:
        _core.testing.set_default_tuning(**previous)


def assert_page_frame(page, expected, *, frame: int = -1, frames: int | None = None,
                      atol: float = 1 / 255, max_outliers: int = 0, min_psnr: float | None = None,
                      out_dir=None, **run_options) -> ImageComparison:
    """Assert that a page's frame matches a reference image (e.g. one test per student page).

    `page` is a softgl.page.PageResult or the path of an HTML page (then run with
    ``softgl.page.run(page, frames=frames or frame + 1 (at least 1), **run_options)``).
    `expected` is an image file (top row first, as saved) or an (h, w, 4) array as readPixels
    returns it (row 0 at the bottom). The comparison is ``assert_images_close``'s, on the frame
    seen upright; on failure the images go to `out_dir` as there."""
    from . import page as _page
    from .io import load_image
    if not isinstance(page, _page.PageResult):
        count = frames if frames is not None else max(1, frame + 1 if frame >= 0 else 1)
        page = _page.run(page, frames=count, **run_options)
    if not page.frames:
        raise AssertionError(f"{page.path.name} drew no frame (it made no WebGL context)")
    actual = page.frames[frame][::-1]
    if isinstance(expected, (str, Path)):
        reference = load_image(expected, np.uint8)
    else:
        reference = np.asarray(expected)[::-1]
    return assert_images_close(actual, reference, atol=atol, max_outliers=max_outliers,
                               min_psnr=min_psnr, name=page.path.stem, out_dir=out_dir)
