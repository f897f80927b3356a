"""softgl.widgets (the explorer's callback logic, headless) and softgl.animation (GIFs)."""
import numpy as np
import pytest

import softgl
from softgl import animation, widgets


def test_render_responds_to_every_kind_of_setting():
    base = widgets.render({}, 96, 72)
    assert base.error is None and base.image.shape == (72, 96, 3)
    assert "gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA" in base.calls
    for change in (dict(src="ONE", dst="ONE"), dict(equation="MAX"), dict(depth_func="GREATER"),
                   dict(red=False), dict(cull="FRONT_AND_BACK"), dict(fog="EXP", fog_density=0.3),
                   dict(antialias="MSAA 4x"), dict(transparency="unsorted"),
                   dict(transparency="exact", opacity=0.7)):
        other = widgets.render(change, 96, 72)
        assert other.error is None, change
        assert (other.image != base.image).any(), change


def test_cull_front_and_back_removes_the_transparent_objects():
    culled = widgets.render(dict(cull="FRONT_AND_BACK"), 96, 72).image
    none = widgets.render(dict(opacity=0.0, src="SRC_ALPHA", dst="ONE_MINUS_SRC_ALPHA"), 96, 72).image
    assert np.abs(culled.astype(int) - none).max() <= 1      # alpha 0 adds nothing either


def test_invalid_state_is_reported_like_a_console():
    r = widgets.render(dict(src="CONSTANT_COLOR", dst="CONSTANT_ALPHA"), 64, 48)
    assert r.error is not None and "blendFunc" in r.error


def test_unknown_settings_are_refused():
    with pytest.raises(ValueError, match="unknown explorer settings"):
        widgets.render(dict(blend="add"))
    with pytest.raises(ValueError, match="choose one of"):
        widgets.render(dict(depth_func="SOMETIMES"))


def test_explorer_callback_updates_the_picture():
    pytest.importorskip("ipywidgets")
    ex = widgets.blend_explorer(96, 72)
    assert ex.renders == 1 and ex.image.value[:8] == b"\x89PNG\r\n\x1a\n"
    before = ex.image.value
    ex.controls["equation"].value = "FUNC_REVERSE_SUBTRACT"     # as a user's click does
    assert ex.renders == 2 and ex.image.value != before
    assert ex.settings["equation"] == "FUNC_REVERSE_SUBTRACT"
    assert "FUNC_REVERSE_SUBTRACT" in ex.calls.value
    ex.controls["alpha"].value = False
    assert ex.renders == 3 and "gl.colorMask(true, true, true, false)" in ex.calls.value
    ex.controls["dst"].value = "CONSTANT_ALPHA"
    ex.controls["src"].value = "CONSTANT_COLOR"                  # WebGL refuses this pair
    assert "INVALID_OPERATION" in ex.calls.value or "blendFunc" in ex.calls.value


def test_explorer_shows_the_live_widget_and_a_picture_for_pages_without_a_kernel(monkeypatch):
    pytest.importorskip("ipywidgets")
    import base64
    import IPython.display
    shown = []
    monkeypatch.setattr(IPython.display, "publish_display_data", lambda data, **kw: shown.append(data))
    ex = widgets.blend_explorer(96, 72, opacity=0.6)
    ex._ipython_display_()
    (bundle,) = shown
    assert bundle["application/vnd.jupyter.widget-view+json"]["model_id"] == ex.widget.model_id
    assert base64.b64decode(bundle["image/png"]) == ex.image.value


def frames(n=5, size=(24, 32)):
    out = []
    for i in range(n):
        gl = softgl.Context(size[1], size[0], antialias=False, preserveDrawingBuffer=True)
        gl.clearColor(i / (n - 1), 0.2, 1 - i / (n - 1), 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
        out.append(gl)
    return out


@pytest.mark.parametrize("backend", ["oiio", "matplotlib"])
def test_frames_to_gif_round_trips(tmp_path, backend):
    if backend == "oiio":
        pytest.importorskip("OpenImageIO")
    fs = frames()
    path = animation.frames_to_gif(fs, tmp_path / "a.gif", fps=5, backend=backend)
    data = path.read_bytes()
    assert data[:6] in (b"GIF89a", b"GIF87a")
    from PIL import Image, ImageSequence
    gif = Image.open(path)
    decoded = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(gif)]
    assert len(decoded) == len(fs)
    for got, frame in zip(decoded, fs):
        want = animation.frame_image(frame).astype(int)
        assert got.shape == want.shape
        assert np.abs(got.astype(int) - want).max() <= 24      # GIF's 256-color palette
    assert gif.info.get("duration") == 200


def test_animation_displays_inline_and_checks_sizes():
    anim = animation.show(frames(3), fps=4)
    assert anim._repr_html_().startswith('<img src="data:image/gif;base64,')
    strip = animation.filmstrip(anim.frames, gap=4)
    assert strip.shape == (24, 3 * 32 + 2 * 4, 3)
    assert anim._repr_png_()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="differ in size"):
        animation.frames_to_gif(frames(2) + frames(2, (8, 8)), "x.gif")


def test_labelled_frames_keep_their_pixels_and_gain_their_label():
    pytest.importorskip("matplotlib")
    fs = frames(2)
    images = [animation.frame_image(f) for f in fs]
    anim = animation.show(fs, fps=4, labels=["light at 0°", "light at 180°"])
    h = images[0].shape[0]
    for got, image in zip(anim.frames, images):
        assert got.shape[0] > h and got.shape[1:] == image.shape[1:]
        assert np.array_equal(got[-h:], image)            # the frame itself, pixel for pixel
        assert (got[:-h] < 128).any()                     # dark text on the white strip above
    assert not np.array_equal(anim.frames[0][:-h], anim.frames[1][:-h])   # each its own label
    with pytest.raises(ValueError, match="2 labels for 3 frames"):
        animation.show(frames(3), labels=["a", "b"])
