"""softgl.experiments: grids draw what they say (checked through properties of the pictures) and
sweeps return tidy tables locally and on a Dask LocalCluster."""
import numpy as np
import pytest

import softgl
from softgl import experiments as X


def test_image_grid_labels_and_empty_cells():
    import matplotlib.pyplot as plt
    img = np.zeros((4, 4, 3), np.uint8)
    fig = X.image_grid([[img, None], [img, img]], ["a", "b"], ["x", "y"], title="t",
                       notes=[["", "no"], ["", ""]])
    axes = fig.axes
    assert len(axes) == 4
    assert [ax.get_title() for ax in axes[:2]] == ["x", "y"]
    assert axes[0].get_ylabel() == "a" and axes[2].get_ylabel() == "b"
    assert len(axes[1].images) == 0 and axes[1].texts[0].get_text() == "no"
    plt.close(fig)


def test_render_blend_rejects_what_webgl_rejects():
    assert X.render_blend("CONSTANT_COLOR", "CONSTANT_ALPHA") is None
    assert X.render_blend("CONSTANT_ALPHA", "ONE_MINUS_CONSTANT_COLOR", version=1) is None
    assert X.render_blend("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA").shape == (64, 64, 3)


def test_blend_factors_zero_one_keep_destination_and_one_zero_replace_it():
    keep = X.render_blend("ZERO", "ONE", size=32).astype(int)
    replace = X.render_blend("ONE", "ZERO", size=32).astype(int)
    add = X.render_blend("ONE", "ONE", size=32).astype(int)
    # FUNC_ADD with ONE, ONE is the clamped sum of the two others, to one 8-bit step.
    assert np.abs(add - np.minimum(keep + replace, 255)).max() <= 1
    assert (keep != replace).any()
    # MIN and MAX ignore the factors.
    lo = X.render_blend("ZERO", "ZERO", "MIN", size=32).astype(int)
    hi = X.render_blend("ZERO", "ZERO", "MAX", size=32).astype(int)
    assert (lo == np.minimum(keep, replace)).all() and (hi == np.maximum(keep, replace)).all()


def red_mask(gl):
    img = gl.readPixels(0, 0, 96, 96, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)
    return (img[..., 0] > 200) & (img[..., 1] < 80)


def test_depth_functions_are_complementary():
    masks = {f: red_mask(X.render_depth_function(f)) for f in X.DEPTH_FUNCTIONS}
    assert not masks["NEVER"].any() and masks["ALWAYS"].sum() > 1000
    for a, b in [("LESS", "GEQUAL"), ("GREATER", "LEQUAL"), ("EQUAL", "NOTEQUAL"),
                 ("NEVER", "ALWAYS")]:
        assert not (masks[a] & masks[b]).any(), (a, b)
        assert ((masks[a] | masks[b]) == masks["ALWAYS"]).all(), (a, b)
    assert 0 < masks["LESS"].sum() < masks["ALWAYS"].sum()
    # With depth writes off, the green bar drawn last shows through where the red square is.
    img = X.render_depth_function("ALWAYS", depth_mask=False)
    rgba = img.readPixels(0, 0, 96, 96, img.RGBA, img.UNSIGNED_BYTE)
    assert (rgba[76, 48] == [51, 178, 77, 255]).all()    # NDC y = 0.6: the bar, over the square


def test_points_lesson_columns():
    gl = X.points_lesson(854, 480, show=False)
    img = gl.readPixels(0, 0, 854, 480, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)

    def at(column, row, dx, dy):     # a pixel of a point group, in the lesson's coordinates
        return img[400 - 100 * row + dy, 60 + 100 * column + dx]

    # Where all three opaque points overlap (15..30 px into the group): without depth testing
    # the last drawn (blue) wins, with it the nearest (red).
    assert (at(0, 0, 20, -20) == [0, 0, 255, 255]).all()
    assert (at(1, 0, 20, -20) == [255, 0, 0, 255]).all()
    # Translucent red over black: column 3 (combined blending) lowers the canvas alpha,
    # column 5 (separate) keeps it at 1, column 6 (alpha masked) keeps it too.
    red_only = (-20, 20)
    assert at(2, 3, *red_only)[3] < 255
    assert at(4, 3, *red_only)[3] == 255 and at(5, 3, *red_only)[3] == 255
    assert at(4, 3, *red_only)[0] == 64       # 0.25 * 255
    # Column 8 writes no depth: the farther points blend over the red one (right of the stripe).
    assert at(7, 2, 28, -20)[2] > 0 and at(6, 2, 28, -20)[2] == 0


def frame_brightness(alpha, mode):
    """A function for sweeps: defined at module level only for readability (lambdas work too)."""
    from softgl import geometry, scene
    from softgl import transforms as T
    gl = softgl.Context(16, 16, antialias=False)
    s = scene.Scene(camera=scene.Camera(eye=(0, 0, 5), ortho_height=2.0), background=(0, 0, 0, 1),
                    transparency=mode)
    s.add(geometry.quad(2, 2), shading="constant", color=(1, 0, 0), alpha=alpha,
          model=T.translate(0, 0, 1))
    s.add(geometry.quad(2, 2), shading="constant", color=(0, 0, 1), alpha=alpha)
    img = gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.UNSIGNED_BYTE) if s.render(gl) else None
    return {"red": int(img[0, 0, 0]), "blue": int(img[0, 0, 2])}


GRID = {"alpha": [0.25, 0.75], "mode": ["sorted", "unsorted"]}


def check_table(table):
    assert list(table.columns) == ["alpha", "mode", "red", "blue"]
    assert table[["alpha", "mode"]].values.tolist() == [[0.25, "sorted"], [0.25, "unsorted"],
                                                        [0.75, "sorted"], [0.75, "unsorted"]]
    sorted_ = table[table["mode"] == "sorted"]
    # Sorted: red (nearer) is blended last, so it dominates.
    assert (sorted_["red"] > sorted_["blue"]).all()
    assert (table[table["mode"] == "unsorted"]["blue"] > 0).all()


def test_sweep_in_this_process():
    check_table(X.sweep(frame_brightness, GRID, processes=0, progress=False))


def test_sweep_local_processes_with_a_lambda():
    table = X.sweep(lambda **p: frame_brightness(**p), GRID, processes=2, progress=False)
    check_table(table)
    scalar = X.sweep(lambda x: x * x, [{"x": 1}, {"x": 3}], processes=2, progress=False)
    assert scalar["result"].tolist() == [1, 9]


def test_sweep_on_a_dask_local_cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        table = X.sweep(frame_brightness, GRID, client=client, progress=False)
        check_table(table)
        # The calls ran on the workers, not here.
        assert len(client.scheduler_info()["workers"]) == 2
