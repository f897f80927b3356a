"""softgl.testing.assert_images_close: it must fail when images differ beyond the limits, pass
when they do not, and leave loadable images behind on failure."""
import math

import numpy as np
import OpenImageIO  # noqa: F401
import pytest

import softgl
from softgl.io import load_image
from softgl.testing import assert_images_close, compare_images


def gradient(h=6, w=8, c=4):
    """A deterministic uint8 image with varied values in every channel."""
    return (np.arange(h * w * c).reshape(h, w, c) * 7 % 251).astype(np.uint8)


def fails(actual, expected, tmp_path, **kwargs):
    """Run the assertion expecting it to fail; return its message."""
    with pytest.raises(AssertionError) as info:
        assert_images_close(actual, expected, out_dir=tmp_path, **kwargs)
    return str(info.value)


def test_identical_images_pass_with_exact_statistics(tmp_path):
    img = gradient()
    stats = assert_images_close(img, img.copy(), atol=0, out_dir=tmp_path)
    assert stats.outliers == 0 and stats.max_error == 0 and stats.psnr == math.inf
    assert not any(tmp_path.iterdir()), "nothing is written when the images agree"


def test_one_step_passes_two_steps_fail(tmp_path):
    expected = gradient()
    one, two = expected.copy(), expected.copy()
    one[2, 3, 1] += 1
    two[2, 3, 1] += 2
    assert assert_images_close(one, expected, out_dir=tmp_path).outliers == 0
    message = fails(two, expected, tmp_path, name="two steps")
    assert "1 pixels beyond atol" in message and "max error" in message
    assert "row 2, column 3, channel 1" in message and "(2/255)" in message
    assert str(tmp_path / "two_steps") in message


def test_whole_ramp_one_step_off_passes_at_one_step(tmp_path):
    # OpenImageIO's float32 differences exceed 1/255 by a few ulps for some values; a one-step
    # tolerance must still accept every one-step difference.
    ramp = np.arange(256, dtype=np.uint8).reshape(16, 16, 1)
    shifted = np.minimum(ramp.astype(int) + 1, 255).astype(np.uint8)
    assert assert_images_close(shifted, ramp, atol=1 / 255, out_dir=tmp_path).outliers == 0
    assert "255 pixels beyond atol" in fails(shifted, ramp, tmp_path, atol=0)
    assert "255 pixels beyond atol" in fails(shifted, ramp, tmp_path, atol=0.99 / 255)


def test_failure_writes_loadable_actual_expected_and_diff(tmp_path):
    expected = gradient()
    actual = expected.copy()
    actual[4, 5] = [0, 0, 0, 0]           # far off: beyond atol
    actual[1, 1, 0] += 1                  # within atol
    fails(actual, expected, tmp_path, name="writes")
    folder = tmp_path / "writes"
    np.testing.assert_array_equal(load_image(folder / "actual.png"), actual)
    np.testing.assert_array_equal(load_image(folder / "expected.png"), expected)
    diff = load_image(folder / "diff.png")
    assert diff.shape == (6, 8, 3)
    assert diff[4, 5].tolist() == [255, 0, 0]          # beyond atol: red
    assert diff[1, 1].tolist() == [255, 255, 255]      # largest error within atol: white
    assert diff[0, 0].tolist() == [0, 0, 0]            # equal: black


def test_shape_mismatch_fails_and_writes_both_images(tmp_path):
    img = gradient()
    assert "differ in shape" in fails(img, img[:5], tmp_path, name="rows")
    assert "differ in shape" in fails(img, img[..., :3], tmp_path, name="channels")
    assert (tmp_path / "rows" / "actual.png").exists() and (tmp_path / "rows" / "expected.png").exists()
    assert not (tmp_path / "rows" / "diff.png").exists()


def test_outliers_count_pixels_not_channels(tmp_path):
    expected = gradient()
    actual = expected.copy()
    actual[0, 0] = 255 - actual[0, 0]         # all four channels of one pixel
    actual[3, 4, 2] ^= 0x40
    actual[5, 7, 3] ^= 0x40
    assert compare_images(actual, expected).outliers == 3
    assert assert_images_close(actual, expected, max_outliers=3, out_dir=tmp_path).outliers == 3
    assert "3 pixels beyond atol, more than max_outliers=2" in fails(actual, expected, tmp_path,
                                                                     max_outliers=2)


def test_psnr_matches_numpy_and_min_psnr_is_enforced(tmp_path):
    rng = np.random.default_rng(7)
    expected = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    noise = rng.integers(-3, 4, expected.shape)
    actual = np.clip(expected.astype(int) + noise, 0, 255).astype(np.uint8)
    err = (actual.astype(np.float64) - expected) / 255
    psnr = 20 * math.log10(1 / math.sqrt((err ** 2).mean()))
    stats = compare_images(actual, expected)
    assert stats.psnr == pytest.approx(psnr, abs=1e-3)
    assert stats.max_error == pytest.approx(np.abs(err).max(), abs=1e-6)
    assert stats.mean_error == pytest.approx(np.abs(err).mean(), abs=1e-6)
    loose = dict(atol=1.0, out_dir=tmp_path)   # only PSNR decides here
    assert_images_close(actual, expected, min_psnr=psnr - 0.1, **loose)
    assert "below min_psnr" in fails(actual, expected, tmp_path, atol=1.0, min_psnr=psnr + 0.1)


def test_float_reference_against_uint8(tmp_path):
    img = gradient()
    reference = img / 255.0                          # float64 formula result
    assert_images_close(img, reference, atol=0.5 / 255, out_dir=tmp_path)
    reference[3, 3, 3] += 0.6 / 255
    assert "1 pixels beyond atol" in fails(img, reference, tmp_path, atol=0.5 / 255)


def test_non_finite_values_fail_unless_equal(tmp_path):
    a = np.zeros((3, 4, 4), np.float32)
    b = a.copy()
    b[1, 2, 0] = np.nan
    assert "inf" in fails(a, b, tmp_path)
    c = a.copy()
    c[0, 0, 3] = np.inf
    assert compare_images(a, c).outliers == 1
    both = b.copy()
    both[0, 0, 3] = np.inf
    assert assert_images_close(both, both.copy(), atol=0, out_dir=tmp_path).outliers == 0


def test_grayscale_and_contexts_are_images(tmp_path):
    assert_images_close(np.zeros((2, 3), np.uint8), np.zeros((2, 3, 1), np.uint8), out_dir=tmp_path)
    gl = softgl.Context(4, 3)
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 0, 4, 1)                 # the bottom row of the canvas
    gl.clearColor(0, 1, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    canvas = np.full((3, 4, 4), [255, 0, 0, 255], np.uint8)
    canvas[2] = [0, 255, 0, 255]           # a context compares as its canvas, top row first
    assert_images_close(gl, canvas, atol=0, out_dir=tmp_path)
    assert "8 pixels beyond atol" in fails(gl, canvas[::-1], tmp_path)   # upside down


def test_default_folder_is_named_after_the_test(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    img = gradient()
    with pytest.raises(AssertionError, match="no images written"):
        assert_images_close(img, 255 - img)          # nothing written unless asked
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(AssertionError):
        assert_images_close(img, 255 - img, out_dir=tmp_path / "out")
    assert (tmp_path / "out" / "test_default_folder_is_named_after_the_test" / "diff.png").exists()


def test_bad_inputs_raise(tmp_path):
    with pytest.raises(TypeError):
        assert_images_close(np.zeros((2, 2, 4), np.int32), np.zeros((2, 2, 4), np.int32), out_dir=tmp_path)
    with pytest.raises(ValueError):
        assert_images_close(np.zeros((0, 2, 4), np.uint8), np.zeros((0, 2, 4), np.uint8), out_dir=tmp_path)
    with pytest.raises(ValueError):
        compare_images(np.zeros((2, 2, 4), np.uint8), np.zeros((2, 3, 4), np.uint8))


# --- the golden fixture, run in inner pytest sessions -------------------------------------------

# pytester runs the inner sessions in this process and afterwards forgets the modules imported
# since the test began; the nanobind extension OpenImageIO aborts when imported twice, hence the
# import of OpenImageIO at the top of this module.
pytest_plugins = ["pytester"]

INNER_TEST = """
from pathlib import Path

import numpy as np


def picture():
    value = int(Path(__file__).with_name("value.txt").read_text())
    img = np.zeros((4, 6, 4), np.uint8)
    img[..., 3] = 255
    img[1:3, 2:5, 0] = value
    return img


def test_exact(golden):
    golden("demo/pic", picture())


def test_tolerant(golden):
    golden("demo/tolerant", picture(), atol=3 / 255)
"""


@pytest.fixture
def inner(pytester):
    """An inner pytest project wired like the real one; run(value, *args) runs it."""
    pytester.makeini("[pytest]\n")
    pytester.makeconftest('pytest_plugins = ["softgl.pytest_plugin"]\n')
    pytester.makepyfile(test_pic=INNER_TEST)

    def run(value, *args):
        (pytester.path / "value.txt").write_text(str(value))
        # (hypothesis's plugin would re-import hypothesis on every run: a second each)
        return pytester.runpytest("-p", "no:cacheprovider", "-p", "no:hypothesispytest", *args)
    return run


def test_golden_missing_then_written_then_compared(inner, pytester):
    goldens = pytester.path / "tests" / "goldens" / "demo"
    result = inner(100)
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*golden*pic.png does not exist*--update-goldens*"])
    assert not (pytester.path / "test-failures").exists()       # not in the working directory
    result.stdout.fnmatch_lines(["*This test's image is *golden-demo-pic*actual.png*"])
    inner(100, "--image-failures", "kept").assert_outcomes(failed=2)
    assert (pytester.path / "kept" / "golden-demo-pic" / "actual.png").exists()
    assert not goldens.exists()

    result = inner(100, "--update-goldens")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*golden images written*", "created *demo*pic.png"])
    written = load_image(goldens / "pic.png")
    assert written.shape == (4, 6, 4) and written[1, 2, 0] == 100 and written[0, 0].tolist() == [0, 0, 0, 255]

    inner(100).assert_outcomes(passed=2)


def test_golden_catches_a_changed_image(inner, pytester):
    inner(100, "--update-goldens").assert_outcomes(passed=2)
    stored = (pytester.path / "tests" / "goldens" / "demo" / "pic.png").read_bytes()

    result = inner(103)             # three 8-bit steps: beyond the default atol, within 3/255
    result.assert_outcomes(failed=1, passed=1)
    result.stdout.fnmatch_lines(["*test_exact*", "*images 'golden-demo-pic' differ*6 pixels beyond atol*",
                                 "*images written to *golden-demo-pic*"])
    assert not (pytester.path / "test-failures").exists()
    inner(103, "--image-failures", "kept").assert_outcomes(failed=1, passed=1)
    assert (pytester.path / "kept" / "golden-demo-pic" / "diff.png").exists()

    # Updating rewrites only the golden that changed beyond its tolerance.
    result = inner(103, "--update-goldens")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["updated *demo*pic.png"])
    result.stdout.no_fnmatch_line("*tolerant.png*")
    assert (pytester.path / "tests" / "goldens" / "demo" / "pic.png").read_bytes() != stored
    inner(103).assert_outcomes(passed=2)


def test_golden_names_stay_inside_the_folder(pytester):
    from softgl.pytest_plugin import _golden_path
    root = pytester.path
    assert _golden_path(root, "blend/additive") == root / "blend" / "additive.png"
    for bad in ["../escape", "/abs", "a//b", "a b", ""]:
        with pytest.raises(ValueError):
            _golden_path(root, bad)
