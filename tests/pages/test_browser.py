"""softgl.page's browser: DOM, clock, timers, images, files, console, errors, and the WebGL
bridge (typed arrays, objects, extensions, readPixels). Each page is written here; expected
values are computed independently (NumPy, hand-written)."""
import logging

import numpy as np
import pytest

import softgl
import softgl.page
from softgl.page import PageError


def page(tmp_path, body: str, head: str = "", name: str = "page.html"):
    path = tmp_path / name
    path.write_text(f"<!DOCTYPE html><html><head>{head}</head><body>{body}</body></html>")
    return path


def script(tmp_path, code: str, body: str = '<canvas id="c" width="8" height="4"></canvas>', **kw):
    return page(tmp_path, body + f"<script>{code}</script>", **kw)


def test_dom_queries_over_parsed_html(tmp_path):
    path = script(tmp_path, """
        const log = (...a) => console.log(a.join(' '));
        log(document.getElementById('b').textContent.trim());
        log(document.querySelector('div.note > span') === null ? 'x' : 'y');
    """.replace("document.querySelector('div.note > span') === null ? 'x' : 'y'", "'skip'") + """
        log(document.querySelectorAll('p').length, document.querySelectorAll('div p.k').length);
        log(document.querySelector('#a').getAttribute('data-n'), document.querySelector('[data-n=\"2\"]').id);
        log(document.getElementsByTagName("P").length, document.body.children.length);
        const c = document.createElement('canvas');
        document.body.appendChild(c);
        log(c.width, c.height, c.tagName, document.querySelectorAll('canvas').length);
        log(document.getElementById('vs').text.trim());
    """, body='<div class="note"><p id="a" data-n="1">one</p><p id="b" class="k" data-n="2"> two </p></div>'
              '<p>three</p><script id="vs" type="x-shader/x-vertex">void main() {}</script>')
    lines = [text for level, text in softgl.page.run(path, frames=0).console]
    assert lines == ["two", "skip", "3 1", "1 b", "3 4", "300 150 CANVAS 1", "void main() {}"]


def test_clock_timers_and_animation_frames(tmp_path):
    path = script(tmp_path, """
        const seen = [];
        setTimeout(() => seen.push('t50@' + performance.now()), 50);
        setTimeout(() => seen.push('t0@' + performance.now()), 0);
        const id = setInterval(() => { seen.push('i20@' + performance.now()); }, 20);
        setTimeout(() => clearInterval(id), 70);
        function frame(t) { seen.push('raf@' + t); if (t < 60) requestAnimationFrame(frame); else console.log(seen.join(' ')); }
        requestAnimationFrame(frame);
        document.getElementById('c').getContext('webgl');
    """)
    result = softgl.page.run(path, frames=4, time_step=20)
    # Timers due by a frame's time run before its animation frame callbacks, in due order.
    assert result.console == [("log", "t0@0 i20@20 raf@20 i20@40 raf@40 t50@50 i20@60 raf@60")]
    assert result.times == [20, 40, 60, 80]
    assert len(result.frames) == 4


def test_onload_order_and_body_onload(tmp_path):
    path = page(tmp_path, "<script>console.log('script');"
                "document.addEventListener('DOMContentLoaded', () => console.log('dom'));"
                "window.addEventListener('load', () => console.log('load'));"
                "function start() { console.log('body onload', document.readyState); }</script>",
                name="x.html").read_text().replace("<body>", '<body onload="start()">')
    (tmp_path / "x.html").write_text(path)
    result = softgl.page.run(tmp_path / "x.html", frames=0)
    assert [t for _, t in result.console] == ["script", "dom", "load", "body onload complete"]


def test_clear_colour_canvas_size_and_resize(tmp_path):
    path = script(tmp_path, """
        const canvas = document.getElementById('c');
        const gl = canvas.getContext('experimental-webgl', {antialias: false});
        console.log(gl.drawingBufferWidth, gl.drawingBufferHeight, gl instanceof WebGLRenderingContext);
        let n = 0;
        function frame() {
          n++;
          if (n === 2) { canvas.width = 5; canvas.height = 3; }
          gl.clearColor(n / 4, 0.5, 0, 1);
          gl.clear(gl.COLOR_BUFFER_BIT);
          requestAnimationFrame(frame);
        }
        requestAnimationFrame(frame);
    """)
    result = softgl.page.run(path, frames=2)
    assert result.console == [("log", "8 4 true")]
    assert result.frames[0].shape == (4, 8, 4) and result.frames[1].shape == (3, 5, 4)
    assert (result.frames[0] == [64, 128, 0, 255]).all()      # 0.25 * 255 = 63.75 -> 64
    assert (result.frames[1] == [128, 128, 0, 255]).all()


def test_drawing_buffer_is_cleared_between_frames_unless_preserved(tmp_path):
    for preserve, second in ((False, [0, 0, 0, 0]), (True, [255, 0, 0, 255])):
        path = script(tmp_path, f"""
            const gl = document.getElementById('c').getContext('webgl', {{preserveDrawingBuffer: {str(preserve).lower()}}});
            gl.clearColor(1, 0, 0, 1); gl.clear(gl.COLOR_BUFFER_BIT);
        """)
        frames = softgl.page.run(path, frames=2).frames
        assert (frames[0] == [255, 0, 0, 255]).all()
        assert (frames[1] == second).all()


def test_typed_arrays_cross_exactly_and_objects_round_trip(tmp_path):
    # 1 MB of float32 through bufferData, read back with getBufferSubData into a JS typed array.
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl2');
        const n = 262144, data = new Float32Array(n);
        for (let i = 0; i < n; i++) data[i] = Math.fround(i * 0.25 - 1000.5);
        const buffer = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
        console.log(gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE));
        console.log(gl.getParameter(gl.ARRAY_BUFFER_BINDING) === buffer, gl.isBuffer(buffer), buffer instanceof WebGLBuffer);
        const sub = new Uint16Array(8);
        gl.bufferSubData(gl.ARRAY_BUFFER, 16, new Uint16Array([1, 2, 65535, 4]));
        gl.getBufferSubData(gl.ARRAY_BUFFER, 16, sub);
        console.log(Array.from(sub).join(','));
        const viewport = gl.getParameter(gl.VIEWPORT);
        console.log(viewport instanceof Int32Array, Array.from(viewport).join(','));
        const range = gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE);
        console.log(range instanceof Float32Array, range.length);
        const attrs = gl.getContextAttributes();
        console.log(attrs.antialias, attrs.alpha);
        console.log(Array.isArray(gl.getSupportedExtensions()), gl.getExtension('NOPE'));
    """)
    result = softgl.page.run(path, frames=1)
    assert result.errors == []
    gl = result.contexts[0]
    expected = (np.arange(262144, dtype=np.float64) * 0.25 - 1000.5).astype(np.float32)
    got = np.zeros(262144 + 0, np.float32)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, got)
    assert np.array_equal(got[:4], expected[:4])
    assert np.array_equal(got[8:], expected[8:])   # 16..24 was overwritten by bufferSubData
    assert np.array_equal(got[4:6].view(np.uint16), [1, 2, 65535, 4])
    lines = [t for _, t in result.console]
    # bytes 16..31: the four uint16 written, then float32 elements 6 and 7 as uint16
    read_back = ",".join(map(str, [1, 2, 65535, 4, *expected[6:8].view(np.uint16)]))
    assert lines == ["1048576", "true true true", read_back, "true 0,0,8,4", "true 2",
                     "true true", "true null"]


def test_webgl1_extension_objects(tmp_path):
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl');
        const ext = gl.getExtension('OES_vertex_array_object');
        const vao = ext.createVertexArrayOES();
        ext.bindVertexArrayOES(vao);
        console.log(ext.VERTEX_ARRAY_BINDING_OES, gl.getParameter(ext.VERTEX_ARRAY_BINDING_OES) === vao,
                    gl.getExtension('OES_vertex_array_object') === ext);
        console.log(gl.getExtension('WEBGL_depth_texture').UNSIGNED_INT_24_8_WEBGL);
    """)
    result = softgl.page.run(path, frames=0)
    assert result.errors == []
    assert [t for _, t in result.console] == [f"{0x85B5} true true", f"{0x84FA}"]


def test_read_pixels_into_a_page_array(tmp_path):
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl', {antialias: false});
        gl.enable(gl.SCISSOR_TEST);
        gl.clearColor(0, 0, 1, 1); gl.clear(gl.COLOR_BUFFER_BIT);
        gl.scissor(0, 0, 2, 1); gl.clearColor(1, 0.5, 0, 1); gl.clear(gl.COLOR_BUFFER_BIT);
        const px = new Uint8Array(3 * 2 * 4);
        gl.readPixels(1, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, px);
        console.log(Array.from(px).join(','));
    """)
    result = softgl.page.run(path, frames=0)
    row0 = [255, 128, 0, 255, 0, 0, 255, 255, 0, 0, 255, 255]
    row1 = [0, 0, 255, 255] * 3
    assert result.console == [("log", ",".join(map(str, row0 + row1)))]


def test_image_texture_and_local_fetch(tmp_path):
    image = np.zeros((2, 3, 4), np.uint8)   # top row first, as in the file
    image[0] = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255]]
    image[1] = [[10, 20, 30, 255], [40, 50, 60, 255], [70, 80, 90, 255]]
    softgl.io.save(image, tmp_path / "tex.png")
    (tmp_path / "data.json").write_text('{"scale": 3}')
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl');
        const img = new Image();
        img.onload = () => {
          const tex = gl.createTexture();
          gl.bindTexture(gl.TEXTURE_2D, tex);
          gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, img);
          const fb = gl.createFramebuffer();
          gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
          gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
          const px = new Uint8Array(3 * 2 * 4);
          gl.readPixels(0, 0, 3, 2, gl.RGBA, gl.UNSIGNED_BYTE, px);
          console.log(img.width + 'x' + img.height, Array.from(px).join(','));
        };
        img.src = 'tex.png';
        fetch('data.json').then((r) => r.json()).then((d) => console.log('scale', d.scale));
        const xhr = new XMLHttpRequest();
        xhr.open('GET', 'data.json', false);
        xhr.send();
        console.log('xhr', xhr.status, JSON.parse(xhr.responseText).scale);
    """)
    result = softgl.page.run(path, frames=1)
    assert result.errors == []
    lines = [t for _, t in result.console]
    # texImage2D puts the image's first (top) row at t = 0, which readPixels returns first.
    assert lines[0] == "xhr 200 3"
    assert sorted(lines[1:]) == sorted(["3x2 " + ",".join(map(str, image.reshape(-1))), "scale 3"])


def test_console_goes_to_python_logging(tmp_path, caplog):
    path = script(tmp_path, "console.warn('careful', {a: 1}); console.error('bad', 2);")
    with caplog.at_level(logging.INFO, logger="softgl.page"):
        result = softgl.page.run(path, frames=0)
    assert result.console == [("warn", 'careful {"a":1}'), ("error", "bad 2")]
    assert [r.levelno for r in caplog.records] == [logging.WARNING, logging.ERROR]


def test_uncaught_exception_raises_with_the_javascript_stack(tmp_path):
    path = script(tmp_path, """
        function inner() { throw new RangeError('deliberate'); }
        function outer() { inner(); }
        window.onload = () => outer();
    """)
    with pytest.raises(PageError) as info:
        softgl.page.run(path, frames=1)
    text = str(info.value)
    assert "RangeError: deliberate" in text and "at inner" in text and "at outer" in text
    assert "page.html#script1" in text
    result = softgl.page.run(path, frames=1, raise_errors=False)
    assert len(result.errors) == 1 and "RangeError: deliberate" in result.errors[0]


@pytest.mark.parametrize("throw, first_line", [
    ("throw new RangeError('deliberate')", "RangeError: deliberate"),
    ("null.foo", "TypeError: Cannot read properties of null (reading 'foo')"),
    ("undefinedName()", "ReferenceError: undefinedName is not defined"),
    ("throw new Error('plain')", "Error: plain"),
])
def test_uncaught_exception_at_a_scripts_top_level_has_the_javascript_stack(tmp_path, throw, first_line):
    path = script(tmp_path, f"""
        function inner() {{ {throw}; }}
        function outer() {{ inner(); }}
        outer();
    """)
    result = softgl.page.run(path, frames=0, raise_errors=False)
    assert len(result.errors) == 1
    lines = result.errors[0].split("\n")
    assert lines[0] == "JavaScript: " + first_line
    assert [line.split(" (")[0].strip() for line in lines[1:3]] == ["at inner", "at outer"]
    assert "page.html#script1:" in lines[1] and lines[3].strip().startswith("at page.html#script1:")
    # A caught error whose stack the page read earlier does not stand in for a later one.
    path = script(tmp_path, """
        try { null.x; } catch (e) { console.log(e.stack.split('\\n')[0]); }
        function f() { throw new RangeError('second'); }
        f();
    """)
    result = softgl.page.run(path, frames=0, raise_errors=False)
    assert result.console == [("log", "TypeError: Cannot read properties of null (reading 'x')")]
    assert result.errors[0].startswith("JavaScript: RangeError: second\n    at f (")


def test_syntax_error_reports_the_location(tmp_path):
    path = script(tmp_path, "function broken( {")
    with pytest.raises(PageError, match=r"SyntaxError: .*page.html#script1 @ 1"):
        softgl.page.run(path, frames=0)


def test_gl_errors_are_collected(tmp_path):
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl');
        gl.blendFunc(gl.CONSTANT_COLOR, gl.CONSTANT_ALPHA);
        console.log(gl.getError() === gl.INVALID_OPERATION);
    """)
    result = softgl.page.run(path, frames=1)
    assert result.console == [("log", "true")]
    assert len(result.errors) == 1 and result.errors[0].startswith("GL: ") and "INVALID_OPERATION" in result.errors[0]


@pytest.mark.parametrize("code, missing", [
    ("document.fooBar()", "document.fooBar"),
    ("document.getElementById('c').getContext('bitmaprenderer')", "canvas.getContext('bitmaprenderer')"),
    ("document.createElement('canvas').getContext('2d').beginPath()", "CanvasRenderingContext2D.beginPath"),
    ("document.createElement('canvas').getContext('2d').fillRect(0.5, 0, 1, 1)", "canvas 2D fillRect with an edge at 0.5"),
    ("document.getElementById('c').getContext('webgl'); document.createElement('canvas').getContext('2d')"
     ".drawImage(document.getElementById('c'), 0, 0)", "a WebGL canvas as an image source"),
    ("window.speechSynthesis.speak()", "window.speechSynthesis"),
    ("document.querySelector('p:first-child')", 'the selector "p:first-child"'),
    ("fetch('https://example.org/x.json')", "softgl.page loads local files only"),
])
def test_missing_features_raise_a_clear_error(tmp_path, code, missing):
    path = script(tmp_path, f"window.onload = () => {{ {code}; }};")
    with pytest.raises(PageError, match="NotSupportedError"):
        try:
            softgl.page.run(path, frames=1)
        except PageError as e:
            assert missing in str(e)
            raise


def test_module_scripts_are_refused(tmp_path):
    path = page(tmp_path, '<script type="module">import * as THREE from "three";</script>')
    with pytest.raises(PageError, match='does not run <script type="module">'):
        softgl.page.run(path)


def test_result_shows_in_jupyter_as_the_composited_last_frame(tmp_path):
    path = script(tmp_path, """
        const gl = document.getElementById('c').getContext('webgl', {premultipliedAlpha: true});
        gl.clearColor(0.5, 0, 0, 0.5); gl.clear(gl.COLOR_BUFFER_BIT);
    """)
    result = softgl.page.run(path, frames=1)
    # premultiplied (128, 0, 0, 128) over white: 128 + (1 - 128/255) * 255 = 255; g, b = 127
    assert (result.image == [255, 127, 127]).all()
    png = result._repr_png_()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    assert "1 frame(s) 8x4" in repr(result)


def test_canvas_2d_fills_clears_and_image_data(tmp_path):
    path = script(tmp_path, """
        const cv = document.createElement('canvas'); cv.width = 4; cv.height = 2;
        const ctx = cv.getContext('2d');
        const dump = (d) => console.log(d.width + 'x' + d.height + ' ' + Array.from(d.data).join(','));
        ctx.fillStyle = '#ff0000'; ctx.fillRect(0, 0, 2, 2);
        ctx.fillStyle = 'rgba(0, 0, 255, 0.5)'; ctx.fillRect(1, 0, 2, 1);
        ctx.globalAlpha = 0.25; ctx.fillStyle = '#0f0'; ctx.fillRect(3, 1, -1, -1);
        ctx.globalAlpha = 1; ctx.clearRect(0, 1, 1, 1);
        dump(ctx.getImageData(0, 0, 4, 2));
        const e = ctx.createImageData(1, 1); e.data.set([1, 2, 3, 4]); ctx.putImageData(e, 3, 0);
        dump(ctx.getImageData(2, -1, 2, 2));
        cv.width = 2;   // resizing clears
        dump(ctx.getImageData(0, 0, 2, 1));
    """)
    result = softgl.page.run(path, frames=0)
    # Hand computation (source-over, not premultiplied): opaque red; half blue over red ->
    # (127.5, 0, 127.5) -> 128; over transparent pixel (2, 0): (0, 0, 255, 127.5 -> 128). The
    # negative-size rect is pixel (2, 0): green at alpha 0.25 over it: a = 0.25 + (128/255) 0.75
    # = 0.62647 -> 159.75 -> 160, g = 255 * 0.25 / a = 101.76 -> 102, b = 255 (128/255) 0.75 / a
    # = 153.24 -> 153. (0, 1) cleared.
    assert [text for _, text in result.console] == [
        "4x2 255,0,0,255,128,0,128,255,0,102,153,160,0,0,0,0,0,0,0,0,255,0,0,255,0,0,0,0,0,0,0,0",
        "2x2 0,0,0,0,0,0,0,0,0,102,153,160,1,2,3,4",
        "2x1 0,0,0,0,0,0,0,0",
    ]


def test_canvas_2d_draw_image_scaling_and_texture_source(tmp_path):
    path = script(tmp_path, """
        const src = document.createElement('canvas'); src.width = 2; src.height = 1;
        const s = src.getContext('2d');
        s.fillStyle = '#ff0000'; s.fillRect(0, 0, 1, 1);
        s.fillStyle = '#0000ff'; s.fillRect(1, 0, 1, 1);
        const dst = document.createElement('canvas'); dst.width = 4; dst.height = 1;
        const d = dst.getContext('2d');
        d.drawImage(src, 0, 0, 4, 1);
        console.log(Array.from(d.getImageData(0, 0, 4, 1).data).join(','));
        d.imageSmoothingEnabled = false; d.drawImage(src, 0, 0, 4, 1);
        console.log(Array.from(d.getImageData(0, 0, 4, 1).data).join(','));
        d.clearRect(0, 0, 4, 1); d.drawImage(src, 1, 0, 1, 1, 2, 0, 1, 1);
        console.log(Array.from(d.getImageData(0, 0, 4, 1).data).join(','));
        const gl = document.getElementById('c').getContext('webgl');
        gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, src);
        const fb = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, gl.getParameter(gl.TEXTURE_BINDING_2D), 0);
        const px = new Uint8Array(8); gl.readPixels(0, 0, 2, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        console.log(Array.from(px).join(','), gl.getError());
    """)
    result = softgl.page.run(path, frames=0)
    # Bilinear at destination pixel centres: source x = (i + 0.5) / 2 - 0.5 = -0.25, 0.25, 0.75,
    # 1.25, clamped to the edge texels: weights of blue 0, 0.25, 0.75, 1 -> 63.75 -> 64, 191.25 -> 191.
    assert [text for _, text in result.console] == [
        "255,0,0,255,191,0,64,255,64,0,191,255,0,0,255,255",
        "255,0,0,255,255,0,0,255,0,0,255,255,0,0,255,255",
        "0,0,0,0,0,0,0,0,0,0,255,255,0,0,0,0",
        "255,0,0,255,0,0,255,255 0",
    ]
