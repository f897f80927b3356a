"""The Python half of softgl.page's browser: the V8 engine (STPyV8), the page's files, the clock,
and one softgl Context per WebGL canvas, bridged so that a JavaScript ``gl.*`` call is a softgl call.

The JavaScript half (browser.js) holds the DOM and the event loop; this module parses the HTML
(html5lib), runs the scripts, advances the frame clock and reads each frame back. Why STPyV8 and
how typed arrays cross without per-element work: docs/pages.md.
"""
from __future__ import annotations

import json
import logging
import warnings
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np

from .. import _core, io as _io
from ..context import Context, Extension
from .canvas2d import Canvas2D

log = logging.getLogger("softgl.page")
log.addHandler(logging.NullHandler())   # a library: shown only where the application configures logging

_JS = (Path(__file__).with_name("browser.js")).read_text(encoding="utf-8")
_DTYPES = {"int8": np.int8, "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16,
           "int32": np.int32, "uint32": np.uint32, "float32": np.float32, "float64": np.float64}
_KINDS = {np.dtype(v): k for k, v in _DTYPES.items()}
# Context methods that are softgl's own (not WebGL's): a page never sees them.
_PYTHON_ONLY = {"stats", "last_draw_plan", "fragments", "canvas", "version"}
# Where <script src> and other relative URLs are looked for after the page's own folder:
# Debian installs JavaScript libraries (libjs-three: three/three.js) under /usr/share/javascript.
LIBRARY_PATH = (Path("/usr/share/javascript"),)


class PageError(RuntimeError):
    """An uncaught JavaScript exception (the message holds the JavaScript stack), or a page that
    needs something softgl.page does not provide (NotSupportedError in the stack names it)."""


def _stpyv8():
    try:
        import STPyV8
    except ImportError as e:   # pragma: no cover - depends on the install
        raise ImportError("softgl.page needs the JavaScript engine STPyV8: pip install 'softgl[pages]'") from e
    return STPyV8


class _Bytes:
    """Receives a typed array's bytes from JavaScript as Latin-1 strings (one char per byte)."""

    def __init__(self, kind: str, length: int):
        self.dtype = _DTYPES[kind]
        self.parts = []
        self.length = length

    def add(self, text: str):
        self.parts.append(text.encode("latin-1"))

    def array(self):
        data = b"".join(self.parts)
        if len(data) != self.length:   # pragma: no cover - a bridge fault, never the page's
            raise RuntimeError(f"softgl.page: {len(data)} bytes arrived, {self.length} were sent")
        return np.frombuffer(data, self.dtype)


class _LoadedImage:
    def __init__(self, pixels: np.ndarray):
        self.pixels = pixels
        self.height, self.width = pixels.shape[:2]


class PageContext:
    """What the page's WebGL context object calls: softgl's methods with JavaScript values
    converted (typed arrays to NumPy, wrappers to softgl objects) and results converted back."""

    def __init__(self, browser: "Browser", canvas, gl: Context):
        self.browser, self.canvas_element, self.gl = browser, canvas, gl
        self.names = sorted(n for n in dir(gl) if not n.startswith("_") and not n.isupper()
                            and n not in _PYTHON_ONLY and callable(getattr(gl, n, None)))

    def method_names(self):
        return self.browser.js_array(self.names)

    def constants(self):
        version = self.gl.version
        return self.browser.js_array([self.browser.js_array([name, value])
                                      for name, value, since in _core.ENUMS if since <= version])

    def size(self):
        return self.browser.js_array([self.gl.drawingBufferWidth, self.gl.drawingBufferHeight])

    def resize(self, width, height):
        self.gl.canvas.width, self.gl.canvas.height = int(width), int(height)

    def method(self, name: str):
        return self.browser.converting(getattr(self.gl, name), f"gl.{name}")

    def method_into(self, name: str, index: int):
        """A method that writes into its argument `index` (readPixels, getBufferSubData): softgl
        writes into a copy of the page's array, whose bytes go back to the page's array."""
        fn = getattr(self.gl, name)

        def call(*args):
            args = list(args)
            dest = np.array(args[index])   # writable copy of the page's bytes
            args[index] = dest
            if name == "readPixels" and len(args) > 7:   # WebGL 2 dstOffset: a view from there
                args[index] = dest[int(args.pop(7)):]
            fn(*args)
            return dest.view(np.uint8).tobytes().decode("latin-1")
        return call


class Browser:
    """One page in one V8 context. Use softgl.page.run(); this is its machinery."""

    def __init__(self, path, *, window_size=(800, 600), library_path=LIBRARY_PATH,
                 context_options=None):
        STPyV8 = _stpyv8()
        self.JSArray, self.JSObject = STPyV8.JSArray, STPyV8.JSObject
        self.path = Path(path).resolve()
        self.folder = self.path.parent
        self.library_path = [Path(p) for p in library_path]
        self.context_options = dict(context_options or {})
        self.page_url = self.path.as_uri()
        self.window_size = tuple(window_size)
        self.console_lines: list[tuple[str, str]] = []
        self.js_errors: list[str] = []
        self.contexts: list[PageContext] = []
        self.wrappers: dict[int, tuple] = {}
        self.js = None
        self.ctx = STPyV8.JSContext()
        self.ctx.__enter__()
        setattr(self.ctx.locals, "__softgl_host", self)   # (setattr: no name mangling)
        self.ctx.eval(_JS, "softgl/page/browser.js")

    def close(self):
        if self.ctx is not None:
            self.ctx.__exit__(None, None, None)
            self.ctx = None

    # -- called from JavaScript ------------------------------------------------------------------
    def attach(self, handles):
        self.js = handles

    def js_error(self, stack: str):
        self.js_errors.append(str(stack))
        log.error("uncaught JavaScript exception: %s", stack)

    def console(self, level: str, parts):
        text = " ".join(str(p) for p in parts)
        self.console_lines.append((str(level), text))
        log.log({"error": logging.ERROR, "warn": logging.WARNING, "alert": logging.WARNING,
                 "debug": logging.DEBUG}.get(level, logging.INFO), "console.%s: %s", level, text)

    def bytes_begin(self, kind: str, length):
        return _Bytes(kind, int(length))

    def typed(self, kind: str, text: str):
        """A typed array's bytes (one Latin-1 character each) as a NumPy array of its type."""
        return np.frombuffer(text.encode("latin-1"), _DTYPES[kind])

    def numbers(self, kind: str, text: str):
        """A JavaScript array of numbers (sent as int32 or float64 bytes) as a Python list."""
        return np.frombuffer(text.encode("latin-1"), _DTYPES[kind]).tolist()

    def small(self, kind: str, values):
        items = list(values)
        if kind == "list":
            return items
        return np.array(items, _DTYPES[kind])

    def resolve(self, url: str) -> Path:
        """A page URL as a local file: relative to the page, then to the library path."""
        parsed = urlparse(url)
        if parsed.scheme in ("http", "https", "data", "blob"):
            raise PageError(f"NotSupportedError: softgl.page loads local files only, not {url}")
        if parsed.scheme == "file":
            return Path(unquote(parsed.path))
        relative = unquote(parsed.path)
        candidates = [self.folder / relative] + [p / relative.lstrip("/") for p in self.library_path]
        for c in candidates:
            if c.is_file():
                return c
        raise FileNotFoundError(f"softgl.page: {url} not found (looked in {', '.join(str(c.parent) for c in candidates)})")

    def read_file(self, url: str, encoding: str) -> str:
        data = self.resolve(str(url)).read_bytes()
        return data.decode(encoding)

    def load_image(self, url: str):
        pixels = _io.load_image(self.resolve(str(url)), np.uint8)
        if pixels.ndim == 2:
            pixels = pixels[:, :, None]
        if pixels.shape[2] == 3:   # an <img> is RGBA: opaque where the file has no alpha
            pixels = np.concatenate([pixels, np.full(pixels.shape[:2] + (1,), 255, np.uint8)], axis=2)
        elif pixels.shape[2] == 1:
            pixels = np.concatenate([np.repeat(pixels, 3, axis=2), np.full(pixels.shape[:2] + (1,), 255, np.uint8)], axis=2)
        return _LoadedImage(np.ascontiguousarray(pixels))

    def create_canvas2d(self, width, height):
        return Canvas2D(int(width), int(height))

    def blank_pixels(self, width, height):
        """A canvas without a context as an image: transparent black of its size."""
        return np.zeros((int(height), int(width), 4), np.uint8)

    def image_data_pixels(self, data, width, height):
        """An ImageData (its Uint8ClampedArray's bytes) as an (h, w, 4) image, top row first."""
        return np.asarray(data, np.uint8).reshape(int(height), int(width), 4)

    def create_context(self, canvas, version, attributes):
        attrs = {}
        for name in ("alpha", "depth", "stencil", "antialias", "premultipliedAlpha",
                     "preserveDrawingBuffer", "powerPreference", "failIfMajorPerformanceCaveat",
                     "desynchronized"):
            try:
                value = attributes[name]
            except Exception:
                value = None
            if value is not None:
                attrs[name] = value if isinstance(value, (bool, str)) else bool(value)
        gl = Context(int(canvas.width), int(canvas.height), version=int(version),
                     **{**attrs, **self.context_options})
        page_context = PageContext(self, canvas, gl)
        self.contexts.append(page_context)
        return page_context

    # -- values from Python to JavaScript ---------------------------------------------------------
    def js_array(self, items):
        return self.JSArray(list(items))

    def result(self, r):
        if isinstance(r, np.ndarray):
            kind = _KINDS.get(r.dtype)
            if r.dtype == np.bool_:
                return self.js_array(["list", self.js_array([bool(v) for v in r.reshape(-1)])])
            if kind is None:
                raise TypeError(f"softgl.page: cannot give JavaScript an array of {r.dtype}")
            return self.js_array(["typed", kind, np.ascontiguousarray(r).view(np.uint8).tobytes().decode("latin-1")])
        if isinstance(r, np.generic):
            return r.item()
        name = type(r).__name__
        if name.startswith("WebGL") and type(r).__module__ == _core.__name__:
            if name == "WebGLActiveInfo":
                return self.js_array(["dict", self.js.json(json.dumps({"name": r.name, "size": r.size, "type": r.type}))])
            if name == "WebGLShaderPrecisionFormat":
                return self.js_array(["dict", self.js.json(json.dumps(
                    {"rangeMin": r.rangeMin, "rangeMax": r.rangeMax, "precision": r.precision}))])
            # The page sees one wrapper per softgl object (so === works): JS keeps them by this
            # number; the object is held here so that its id stays its own.
            self.wrappers.setdefault(id(r), r)
            return self.js_array(["object", id(r), name, r])
        if isinstance(r, Extension):
            self.wrappers.setdefault(id(r), r)
            names = [n for n in dir(r) if not n.startswith("_")]
            constants = [self.js_array([n, getattr(r, n)]) for n in names if not callable(getattr(r, n))]
            methods = [n for n in names if callable(getattr(r, n))]
            return self.js_array(["ext", id(r), self.js_array(constants), self.js_array(methods),
                                  lambda n, r=r: self.converting(getattr(r, n), n)])
        if isinstance(r, dict):
            return self.js_array(["dict", self.js.json(json.dumps(
                {k: (v.item() if isinstance(v, np.generic) else v) for k, v in r.items()}))])
        if isinstance(r, (list, tuple)):
            return self.js_array(["list", self.js_array([self._plain(v) for v in r])])
        raise TypeError(f"softgl.page: cannot give JavaScript a {type(r).__name__}")

    def _plain(self, v):
        if v is None or type(v) in (int, float, bool, str):
            return v
        return self.result(v)

    def converting(self, fn, name: str):
        """fn as JavaScript calls it: results other than numbers, strings and None converted."""
        out, js_types = self.result, (self.JSArray, self.JSObject)

        def call(*args):
            if any(isinstance(a, js_types) for a in args):
                self.unsupported_argument(name, args)
            r = fn(*args)
            return r if r is None or type(r) in (int, float, bool, str) else out(r)
        return call

    def unsupported_argument(self, name, args):
        kinds = ", ".join(type(a).__name__ for a in args)
        raise TypeError(f"softgl.page: gl.{name} got a JavaScript value it cannot pass to softgl ({kinds})")

    def run_script(self, source: str, name: str):
        """Run a classic script as a browser does: its top-level const/let/class declarations are
        seen by the scripts after it (so not through eval). An exception thrown at its top level
        is reported with its JavaScript stack (browser.js keeps the last stack V8 formatted:
        STPyV8 turns RangeError, TypeError, ... into Python exceptions with the message and
        location only); a syntax error, or a thrown value that is not an Error, with V8's
        location and source line."""
        self.js.clearLastStack()
        try:
            self.ctx.eval(source, name)
        except Exception as e:   # JavaScript exceptions arrive as Python exceptions
            message = str(getattr(e, "stackTrace", None) or e)
            stack = str(self.js.lastStack())
            if "\n    at " in stack and stack.split("\n", 1)[0] in message:
                message = stack
            self.js_error(message)

    # -- driving the page ---------------------------------------------------------------------------
    def load(self):
        """Parse the HTML, build the DOM, run the scripts in order, then DOMContentLoaded and load."""
        import html5lib
        tree = html5lib.parse(self.path.read_bytes(), treebuilder="etree", namespaceHTMLElements=False)
        scripts = []
        body_onload = []

        def convert(el):
            children = []
            if el.text:
                children.append(el.text)
            for child in el:
                if isinstance(child.tag, str):
                    children.append(convert(child))
                if child.tail:
                    children.append(child.tail)
            item = [el.tag, dict(el.attrib), children]
            if el.tag == "script":
                scripts.append(el)
            if el.tag == "body" and "onload" in el.attrib:
                body_onload.append(el.attrib["onload"])
            return item

        self.js.buildJSON(json.dumps([convert(tree)]))
        for index, script in enumerate(scripts):
            kind = (script.attrib.get("type") or "text/javascript").strip().lower()
            if kind == "module":
                raise PageError("NotSupportedError: softgl.page does not run <script type=\"module\"> "
                                "(use the library's non-module build, e.g. three/three.js)")
            if kind not in ("text/javascript", "application/javascript", "javascript"):
                continue   # shader sources and data blocks are read by the page itself
            src = script.attrib.get("src")
            if src:
                path = self.resolve(src)
                self.run_script(path.read_text(encoding="utf-8"), str(path))
            else:
                self.run_script(script.text or "", f"{self.path.name}#script{index + 1}")
        self.js.fire("document", "DOMContentLoaded")
        self.js.runTimers(0)
        self.js.fire("window", "load")
        for handler in body_onload:
            self.js.runHandler(handler, f"{self.path.name}#body-onload")
