// softgl.page's browser: the DOM, timers, images, fetch and the WebGL context objects a lesson
// page or three.js touches, in JavaScript, over a Python host (softgl/page/browser.py) that
// owns the clock, the files and the softgl Contexts. Everything here is deterministic: no real
// time, no network. A property the page reads that this browser lacks throws an Error that names it
// (see `strict` below), instead of silently being undefined.
'use strict';
(function (global, pyhost) {
  // Python attributes are looked up once: a property read on a Python object costs ~5x a call.
  const host = {};
  for (const name of ['bytes_begin', 'small', 'typed', 'numbers', 'load_image', 'console', 'create_context', 'read_file', 'js_error', 'attach',
    'create_canvas2d', 'blank_pixels', 'image_data_pixels'])
    host[name] = pyhost[name];
  host.page_url = pyhost.page_url; host.window_size = [pyhost.window_size[0], pyhost.window_size[1]];
  // An uncaught exception in a script, an event listener, a timer or an animation frame is
  // reported with its stack; the page goes on, as in a browser (Python raises it afterwards).
  const report = (e) => { host.js_error((e && e.stack) ? String(e.stack) : String(e)); };
  // V8 formats an error's stack when its .stack is first read (through Error.prepareStackTrace,
  // as V8's default would); STPyV8 reads it for an exception escaping a script's top level but
  // gives Python only the message and location (for RangeError, TypeError, ...). The last stack
  // formatted is kept, so that the host reports the whole JavaScript stack of such an error too.
  let lastStack = '';
  Error.prepareStackTrace = (error, frames) => {
    let text;
    try { text = String(error); } catch (e) { text = 'Error'; }
    for (const frame of frames) text += '\n    at ' + frame;
    lastStack = text;
    return text;
  };
  const guarded = (fn, self, args) => { try { return fn.apply(self, args); } catch (e) { report(e); return undefined; } };
  const unsupported = (what) => {
    const e = new Error('softgl.page does not provide ' + what);
    e.name = 'NotSupportedError';
    return e;
  };

  // Objects of the page's world are wrapped so that reading a missing property fails loudly.
  // Names that pages only probe for (feature detection) read as undefined.
  const PROBED = new Set(['then', 'toJSON', 'constructor', 'nodeType', 'ownerDocument', 'getRootNode',
    'msMaxTouchPoints', 'ontouchstart', 'onpointerdown', 'PointerEvent', 'attachEvent', 'webkitRequestAnimationFrame',
    'mozRequestAnimationFrame', 'oRequestAnimationFrame', 'msRequestAnimationFrame', 'webkitCancelAnimationFrame',
    'mozCancelAnimationFrame', 'devicePixelRatio', 'requestIdleCallback', 'mozCancelRequestAnimationFrame',
    'webkitCancelRequestAnimationFrame', 'msCancelAnimationFrame', 'OffscreenCanvas', 'xr', 'inspect',
    'asymmetricMatch', '$$typeof', 'nodeName', 'length', 'valueOf', Symbol.toPrimitive, Symbol.iterator,
    Symbol.toStringTag, 'toString']);
  const strict = (obj, label) => new Proxy(obj, {
    get(target, key, receiver) {
      // Event handler properties (onload, onerror, ...) read as undefined until set, as null in a browser.
      if (key in target || typeof key === 'symbol' || PROBED.has(key) || key.startsWith('__') || /^on[a-z]+$/.test(key)) return Reflect.get(target, key, receiver);
      throw unsupported(label + '.' + String(key));
    },
  });

  // -- events -------------------------------------------------------------------------------
  class EventTarget {
    constructor() { this.__listeners = {}; }
    addEventListener(type, fn) { (this.__listeners[type] = this.__listeners[type] || []).push(fn); }
    removeEventListener(type, fn) {
      const l = this.__listeners[type]; if (!l) return;
      const i = l.indexOf(fn); if (i >= 0) l.splice(i, 1);
    }
    dispatchEvent(event) {
      event.target = event.target || this;
      event.currentTarget = this;
      const handler = this['on' + event.type];
      if (typeof handler === 'function') guarded(handler, this, [event]);
      for (const fn of (this.__listeners[event.type] || []).slice()) {
        if (typeof fn === 'function') guarded(fn, this, [event]); else guarded(fn.handleEvent, fn, [event]);
      }
      return true;
    }
  }
  class Event {
    constructor(type, init) { this.type = type; Object.assign(this, init || {}); this.defaultPrevented = false; }
    preventDefault() { this.defaultPrevented = true; }
    stopPropagation() {}
  }

  // -- the clock: timers and animation frames run only when Python advances it ---------------
  let now = 0, nextId = 1;
  const timers = new Map();       // id -> {due, fn, args, interval}
  let frameCallbacks = new Map(); // id -> fn
  const setTimeout = (fn, ms, ...args) => {
    if (typeof fn !== 'function') throw unsupported('setTimeout with a string of code');
    const id = nextId++;
    timers.set(id, { due: now + Math.max(0, +ms || 0), fn, args, interval: null, order: id });
    return id;
  };
  const setInterval = (fn, ms, ...args) => {
    const id = setTimeout(fn, ms, ...args);
    timers.get(id).interval = Math.max(1, +ms || 0);
    return id;
  };
  const clearTimeout = (id) => { timers.delete(id); };
  const requestAnimationFrame = (fn) => { const id = nextId++; frameCallbacks.set(id, fn); return id; };
  const cancelAnimationFrame = (id) => { frameCallbacks.delete(id); };
  // Runs the timers due by time t (in due order, then creation order), advancing the clock.
  const runTimers = (t) => {
    for (;;) {
      let best = null;
      for (const [id, timer] of timers) {
        if (timer.due <= t && (best === null || timer.due < best[1].due ||
            (timer.due === best[1].due && timer.order < best[1].order))) best = [id, timer];
      }
      if (best === null) break;
      const [id, timer] = best;
      now = Math.max(now, timer.due);
      if (timer.interval !== null) { timer.due += timer.interval; timer.order = nextId++; } else timers.delete(id);
      guarded(timer.fn, global, timer.args);
    }
    now = t;
  };
  const runFrame = (t) => {
    runTimers(t);
    const callbacks = frameCallbacks;
    frameCallbacks = new Map();
    for (const fn of callbacks.values()) guarded(fn, global, [t]);
    return callbacks.size;
  };
  const performance = strict({ now: () => now, timeOrigin: 0, mark() {}, measure() {} }, 'performance');

  // -- bytes between typed arrays and Python (no per-element Python work) --------------------
  const KINDS = new Map([[Int8Array, 'int8'], [Uint8Array, 'uint8'], [Uint8ClampedArray, 'uint8'],
    [Int16Array, 'int16'], [Uint16Array, 'uint16'], [Int32Array, 'int32'], [Uint32Array, 'uint32'],
    [Float32Array, 'float32'], [Float64Array, 'float64'], [DataView, 'uint8']]);
  // A JS string of one Latin-1 character per byte crosses into Python as one str; String.fromCharCode
  // over a subarray is V8's own loop. 64 KiB pieces (V8 converts larger strings more slowly).
  const PIECE = 65536, SUB = 8192;
  const latin1 = (u8, start, end) => {
    const parts = [];
    for (let j = start; j < end; j += SUB) parts.push(String.fromCharCode.apply(null, u8.subarray(j, Math.min(j + SUB, end))));
    return parts.length === 1 ? parts[0] : parts.join('');
  };
  const toPython = (view) => {
    const kind = KINDS.get(view.constructor) || (view instanceof ArrayBuffer ? 'uint8' : null);
    if (kind === null) throw unsupported('typed array ' + view.constructor.name);
    const u8 = view instanceof ArrayBuffer ? new Uint8Array(view) : new Uint8Array(view.buffer, view.byteOffset, view.byteLength);
    if (u8.length <= PIECE) return host.typed(kind, latin1(u8, 0, u8.length));
    const sink = host.bytes_begin(kind, u8.length);
    for (let i = 0; i < u8.length; i += PIECE) sink.add(latin1(u8, i, Math.min(i + PIECE, u8.length)));
    return sink.array();
  };
  // A JS array of numbers (uniform3fv(loc, [x, y, z])) crosses as the bytes of an Int32Array
  // (all integers) or a Float64Array (exact), and arrives as a Python list.
  const numbersToPython = (a) => {
    let ints = true;
    for (let i = 0; i < a.length; i++) {
      const x = a[i];
      if (typeof x !== 'number') return host.small('list', a.map((y) => (y instanceof WebGLObject ? y.__h : y)));
      if (ints && !(Number.isInteger(x) && x >= -2147483648 && x <= 2147483647)) ints = false;
    }
    const typed = ints ? new Int32Array(a) : new Float64Array(a);
    return host.numbers(ints ? 'int32' : 'float64', latin1(new Uint8Array(typed.buffer), 0, typed.byteLength));
  };
  // Python -> JS: a Latin-1 string of the bytes, written into a typed array.
  const fromPython = (kind, text) => {
    const u8 = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) u8[i] = text.charCodeAt(i);
    const Type = { int8: Int8Array, uint8: Uint8Array, int16: Int16Array, uint16: Uint16Array, int32: Int32Array,
      uint32: Uint32Array, float32: Float32Array, float64: Float64Array }[kind];
    return new Type(u8.buffer);
  };

  // -- WebGL objects: JS wrappers around softgl's Python objects, one wrapper per object ------
  class WebGLObject { constructor(handle) { this.__h = handle; } }
  const glClasses = {};
  for (const name of ['WebGLBuffer', 'WebGLTexture', 'WebGLProgram', 'WebGLShader', 'WebGLFramebuffer',
    'WebGLRenderbuffer', 'WebGLUniformLocation', 'WebGLVertexArrayObject', 'WebGLQuery', 'WebGLSampler',
    'WebGLSync', 'WebGLTransformFeedback', 'WebGLActiveInfo', 'WebGLShaderPrecisionFormat']) {
    glClasses[name] = ({ [name]: class extends WebGLObject {} })[name];
  }
  const wrappers = new Map();
  const wrapHandle = (handle, className) => {
    const Cls = glClasses[className];
    if (!Cls) throw unsupported('a WebGL object of type ' + className);
    return new Cls(handle);
  };

  const argToPython = (a) => {
    if (a === null || a === undefined || typeof a !== 'object') return a;
    if (a instanceof WebGLObject) return a.__h;
    if (ArrayBuffer.isView(a) || a instanceof ArrayBuffer) return toPython(a);
    if (Array.isArray(a)) return numbersToPython(a);
    if (a.__pixels !== undefined) return a.__pixels();   // an Image, ImageData or canvas
    return a;
  };
  // The host returns ['typed', kind, latin1], ['list', items], ['dict', object], a wrapper or a plain value.
  const resultFromPython = (r) => {
    if (r === null || typeof r !== 'object') return r;
    const tag = r[0];
    if (tag === 'typed') return fromPython(r[1], r[2]);
    if (tag === 'object') {   // ['object', id, class, handle]: one wrapper per softgl object
      let w = wrappers.get(r[1]);
      if (w === undefined) { w = wrapHandle(r[3], r[2]); wrappers.set(r[1], w); }
      return w;
    }
    if (tag === 'ext') {      // ['ext', id, constants, method names, method getter]
      let ext = wrappers.get(r[1]);
      if (ext === undefined) {
        ext = {};
        for (let i = 0; i < r[2].length; i++) ext[r[2][i][0]] = r[2][i][1];
        for (let i = 0; i < r[3].length; i++) ext[r[3][i]] = converting(r[4](r[3][i]));
        wrappers.set(r[1], ext);
      }
      return ext;
    }
    if (tag === 'list') { const out = []; for (let i = 0; i < r[1].length; i++) out.push(resultFromPython(r[1][i])); return out; }
    if (tag === 'dict') return r[1];
    return r;
  };

  // A JS function over a Python one: arguments to Python values, the result back to JS values.
  const converting = (call) => function (...args) {
    for (let i = 0; i < args.length; i++) {
      const a = args[i];
      if (a !== null && typeof a === 'object') args[i] = argToPython(a);
    }
    const r = call(...args);
    return (r !== null && typeof r === 'object') ? resultFromPython(r) : r;
  };
  const makeContext = (canvas, py, version, methodNames, constants) => {
    const proto = version === 2 ? WebGL2RenderingContext.prototype : WebGLRenderingContext.prototype;
    const gl = Object.create(proto);
    for (let i = 0; i < constants.length; i++) gl[constants[i][0]] = constants[i][1];
    for (let i = 0; i < methodNames.length; i++) gl[methodNames[i]] = converting(py.method(methodNames[i]));
    // Calls that write into the page's typed array: the bytes come back into it.
    for (const [name, index] of [['readPixels', 6], ['getBufferSubData', 2]]) {
      if (!methodNames.includes(name)) continue;
      const call = converting(py.method_into(name, index));
      gl[name] = function (...args) {
        const dest = args[index];
        if (!ArrayBuffer.isView(dest)) throw new TypeError("Failed to execute '" + name + "': parameter " + (index + 1) + ' is not an ArrayBufferView');
        const bytes = call(...args);
        new Uint8Array(dest.buffer, dest.byteOffset, dest.byteLength).set(fromPython('uint8', bytes));
      };
    }
    gl.canvas = canvas;
    Object.defineProperty(gl, 'drawingBufferWidth', { get: () => py.size()[0] });
    Object.defineProperty(gl, 'drawingBufferHeight', { get: () => py.size()[1] });
    gl.__py = py;
    return gl;
  };
  function WebGLRenderingContext() { throw new TypeError('Illegal constructor'); }
  function WebGL2RenderingContext() { throw new TypeError('Illegal constructor'); }

  // -- the DOM ---------------------------------------------------------------------------------
  class Node extends EventTarget {
    constructor() { super(); this.childNodes = []; this.parentNode = null; }
    get parentElement() { return this.parentNode instanceof Element ? this.parentNode : null; }
    get children() { return this.childNodes.filter((n) => n instanceof Element); }
    get firstChild() { return this.childNodes[0] || null; }
    get lastChild() { return this.childNodes[this.childNodes.length - 1] || null; }
    get nextSibling() {
      if (!this.parentNode) return null;
      const c = this.parentNode.childNodes; return c[c.indexOf(this) + 1] || null;
    }
    appendChild(node) {
      if (node.parentNode) node.parentNode.removeChild(node);
      this.childNodes.push(node); node.parentNode = this; return node;
    }
    insertBefore(node, ref) {
      if (ref === null || ref === undefined) return this.appendChild(node);
      if (node.parentNode) node.parentNode.removeChild(node);
      this.childNodes.splice(this.childNodes.indexOf(ref), 0, node); node.parentNode = this; return node;
    }
    removeChild(node) {
      const i = this.childNodes.indexOf(node);
      if (i >= 0) this.childNodes.splice(i, 1);
      node.parentNode = null; return node;
    }
    get textContent() { return this.childNodes.map((n) => n.textContent).join(''); }
    set textContent(v) { this.childNodes = []; this.appendChild(new Text(String(v))); }
    contains(node) { for (let n = node; n; n = n.parentNode) if (n === this) return true; return false; }
  }
  class Text extends Node {
    constructor(data) { super(); this.data = data; this.nodeType = 3; }
    get textContent() { return this.data; }
    set textContent(v) { this.data = String(v); }
  }
  // One compound selector: tag, #id, .class and [attr] / [attr=value] parts; anything else
  // (pseudo-classes, child/sibling combinators) is refused by name.
  const compounds = new Map();
  const parseCompound = (sel) => {
    if (compounds.has(sel)) return compounds.get(sel);
    const re = /([a-zA-Z][\w-]*)|#([\w-]+)|\.([\w-]+)|\[([\w-]+)(?:=["']?([^"'\]]*)["']?)?\]|(\*)/g;
    const parts = [];
    let m, consumed = 0;
    while ((m = re.exec(sel)) !== null && m.index === consumed) { parts.push(m); consumed = re.lastIndex; }
    if (consumed !== sel.length || sel.length === 0) throw unsupported('the selector ' + JSON.stringify(sel));
    compounds.set(sel, parts);
    return parts;
  };
  const matchesSimple = (el, sel) => {
    for (const m of parseCompound(sel)) {
      if (m[1] && el.localName !== m[1].toLowerCase()) return false;
      if (m[2] && el.id !== m[2]) return false;
      if (m[3] && !el.className.split(/\s+/).includes(m[3])) return false;
      if (m[4] && (!el.hasAttribute(m[4]) || (m[5] !== undefined && el.getAttribute(m[4]) !== m[5]))) return false;
    }
    return true;
  };
  const matches = (el, selector) => selector.split(',').some((group) => {
    const parts = group.trim().split(/\s+/);   // descendant combinators only
    if (parts.some((p) => /[>+~]/.test(p))) throw unsupported('the selector combinator in ' + JSON.stringify(selector));
    parts.forEach(parseCompound);
    if (!matchesSimple(el, parts[parts.length - 1])) return false;
    let i = parts.length - 2;
    for (let n = el.parentNode; n && i >= 0; n = n.parentNode) if (n instanceof Element && matchesSimple(n, parts[i])) i--;
    return i < 0;
  });
  const descendants = (root) => {
    const out = [];
    const walk = (n) => { for (const c of n.childNodes) if (c instanceof Element) { out.push(c); walk(c); } };
    walk(root); return out;
  };
  class Element extends Node {
    constructor(localName, attributes) {
      super();
      this.localName = localName; this.nodeType = 1;
      this.__attributes = new Map(Object.entries(attributes || {}));
      this.style = {};
      this.dataset = {};
    }
    get tagName() { return this.localName.toUpperCase(); }
    get nodeName() { return this.tagName; }
    get id() { return this.getAttribute('id') || ''; }
    set id(v) { this.setAttribute('id', v); }
    get className() { return this.getAttribute('class') || ''; }
    set className(v) { this.setAttribute('class', v); }
    getAttribute(name) { return this.__attributes.has(name) ? this.__attributes.get(name) : null; }
    setAttribute(name, value) { this.__attributes.set(name, String(value)); }
    hasAttribute(name) { return this.__attributes.has(name); }
    removeAttribute(name) { this.__attributes.delete(name); }
    get innerHTML() { return this.textContent; }
    set innerHTML(v) {
      if (/[<]/.test(String(v))) throw unsupported('innerHTML with markup');
      this.textContent = v;
    }
    get text() { return this.textContent; }
    get innerText() { return this.textContent; }
    set innerText(v) { this.textContent = v; }
    querySelectorAll(selector) { return descendants(this).filter((el) => matches(el, selector)); }
    querySelector(selector) { return this.querySelectorAll(selector)[0] || null; }
    getElementsByTagName(name) { return descendants(this).filter((el) => name === '*' || el.localName === name.toLowerCase()); }
    getElementsByClassName(name) { return descendants(this).filter((el) => el.className.split(/\s+/).includes(name)); }
    matches(selector) { return matches(this, selector); }
    getBoundingClientRect() {
      const w = this.clientWidth || 0, h = this.clientHeight || 0;
      return { x: 0, y: 0, left: 0, top: 0, right: w, bottom: h, width: w, height: h };
    }
    get clientWidth() { return 0; }
    get clientHeight() { return 0; }
    focus() {}
    blur() {}
    setPointerCapture() {}
    releasePointerCapture() {}
  }
  // Attributes HTML reflects as properties of the same name ('' when absent).
  for (const name of ['type', 'src', 'name', 'title', 'href', 'alt', 'value', 'lang', 'rel', 'charset']) {
    Object.defineProperty(Element.prototype, name, {
      get() { return this.getAttribute(name) || ''; },
      set(v) { this.setAttribute(name, v); },
      configurable: true,
    });
  }
  class HTMLImageElement extends Element {
    constructor(attributes) {
      super('img', attributes);
      this.__image = null; this.__src = ''; this.complete = false;
      this.naturalWidth = 0; this.naturalHeight = 0; this.crossOrigin = null;
    }
    get src() { return this.__src; }
    set src(url) {
      localOnly(url);
      this.__src = String(url);
      // Decoding happens on the clock's task queue, as in a browser: onload fires later.
      setTimeout(() => {
        let image;
        try { image = host.load_image(this.__src); } catch (e) {
          host.console('error', ['softgl.page: failed to load image ' + this.__src + ': ' + e.message]);
          this.dispatchEvent(new Event('error')); return;
        }
        this.__image = image;
        this.naturalWidth = image.width; this.naturalHeight = image.height;
        if (!this.__attributes.has('width')) this.width = image.width;
        if (!this.__attributes.has('height')) this.height = image.height;
        this.complete = true;
        this.dispatchEvent(new Event('load'));
      }, 0);
    }
    decode() { return new Promise((resolve) => { this.addEventListener('load', () => resolve()); }); }
    __pixels() {
      if (!this.__image) throw new Error('softgl.page: image ' + this.__src + ' is used before it has loaded');
      return this.__image.pixels;
    }
  }
  // -- canvas 2D: the exact part pages and three.js use for texture images (softgl/page/canvas2d.py;
  // docs/pages.md, "Canvas 2D"). Anything else on the context is refused by name (strict).
  class ImageData {
    constructor(a, b, c) {
      if (typeof a === 'number') {
        this.width = a >>> 0; this.height = b >>> 0;
        this.data = new Uint8ClampedArray(this.width * this.height * 4);
      } else {
        this.data = a; this.width = b >>> 0;
        this.height = c === undefined ? a.length / 4 / this.width : c >>> 0;
      }
      this.colorSpace = 'srgb';
    }
    __pixels() { return host.image_data_pixels(toPython(this.data), this.width, this.height); }
  }
  const call2d = (fn) => {
    try { return fn(); } catch (e) {
      const m = /canvas 2D [^\n]*/.exec(String(e && e.message !== undefined ? e.message : e));
      if (m) throw unsupported(m[0]);
      throw e;
    }
  };
  class CanvasRenderingContext2D {
    constructor(canvas) {
      this.canvas = canvas;
      this.fillStyle = '#000000'; this.globalAlpha = 1; this.globalCompositeOperation = 'source-over';
      this.imageSmoothingEnabled = true; this.imageSmoothingQuality = 'low';
      this.__py = host.create_canvas2d(canvas.width, canvas.height);
    }
    __checkState(what) {
      if (this.globalCompositeOperation !== 'source-over') throw unsupported("canvas 2D globalCompositeOperation '" + this.globalCompositeOperation + "'");
      if (what === 'fill' && typeof this.fillStyle !== 'string') throw unsupported('a canvas 2D fillStyle that is not a colour (gradients, patterns)');
    }
    fillRect(x, y, w, h) { this.__checkState('fill'); call2d(() => this.__py.fill_rect(+x, +y, +w, +h, this.fillStyle, +this.globalAlpha)); }
    clearRect(x, y, w, h) { call2d(() => this.__py.clear_rect(+x, +y, +w, +h)); }
    drawImage(image, ...args) {
      this.__checkState('image');
      if (!image || image.__pixels === undefined) throw new TypeError("Failed to execute 'drawImage': the source is not an image or a canvas");
      const pixels = image.__pixels();
      call2d(() => this.__py.draw(pixels, args.map(Number), !!this.imageSmoothingEnabled, +this.globalAlpha));
    }
    getImageData(x, y, w, h) {
      const text = call2d(() => this.__py.get_image_data_bytes(+x, +y, +w, +h));
      return new ImageData(new Uint8ClampedArray(fromPython('uint8', text).buffer), Math.abs(w), Math.abs(h));
    }
    putImageData(imageData, dx, dy, ...dirty) {
      if (dirty.length) throw unsupported('putImageData with a dirty rectangle');
      call2d(() => this.__py.put_image_data(toPython(imageData.data), imageData.width, imageData.height, +dx, +dy));
    }
    createImageData(w, h) { return typeof w === 'object' ? new ImageData(w.width, w.height) : new ImageData(Math.abs(w), Math.abs(h)); }
  }

  class HTMLCanvasElement extends Element {
    constructor(attributes) {
      super('canvas', attributes);
      this.__context = null; this.__kind = null;
    }
    get width() { return +(this.getAttribute('width') || 300); }
    set width(v) { this.setAttribute('width', v >>> 0); this.__resized(); }
    get height() { return +(this.getAttribute('height') || 150); }
    set height(v) { this.setAttribute('height', v >>> 0); this.__resized(); }
    __resized() {
      if (this.__context) this.__context.__py.resize(this.width, this.height);   // a 2D canvas is cleared too
    }
    get clientWidth() { return this.width; }
    get clientHeight() { return this.height; }
    getContext(kind, attributes) {
      if (kind === '2d') {
        if (this.__context) return this.__kind === '2d' ? this.__context : null;
        this.__context = strict(new CanvasRenderingContext2D(this), 'CanvasRenderingContext2D');
        this.__kind = '2d';
        return this.__context;
      }
      const version = { webgl: 1, 'experimental-webgl': 1, webgl2: 2 }[kind];
      if (version === undefined) {
        if (kind === 'bitmaprenderer' || kind === 'webgpu') throw unsupported("canvas.getContext('" + kind + "')");
        return null;
      }
      if (this.__context) return this.__kind === version ? this.__context : null;
      const py = host.create_context(this, version, attributes || {});
      this.__context = makeContext(this, py, version, py.method_names(), py.constants());
      this.__kind = version;
      return this.__context;
    }
    toDataURL() { throw unsupported('canvas.toDataURL'); }
    // As an image (texImage2D, drawImage): a 2D canvas's pixels; a canvas without a context is
    // transparent black; a WebGL canvas is not provided.
    __pixels() {
      if (this.__kind === '2d') return this.__context.__py.pixels;
      if (this.__context) throw unsupported('a WebGL canvas as an image source');
      return host.blank_pixels(this.width, this.height);
    }
  }
  const makeElement = (localName, attributes) => {
    if (localName === 'canvas') return strict(new HTMLCanvasElement(attributes), '<canvas>');
    if (localName === 'img') return strict(new HTMLImageElement(attributes), '<img>');
    return strict(new Element(localName, attributes), '<' + localName + '>');
  };
  class Document extends Node {
    constructor() { super(); this.readyState = 'loading'; this.nodeType = 9; }
    get documentElement() { return this.children[0] || null; }
    get body() { return this.querySelector('body'); }
    get head() { return this.querySelector('head'); }
    createElement(name) { return makeElement(String(name).toLowerCase(), {}); }
    createElementNS(ns, name) { return this.createElement(name); }
    createTextNode(text) { return new Text(String(text)); }
    getElementById(id) { return descendants(this).find((el) => el.id === id) || null; }
    querySelectorAll(selector) { return descendants(this).filter((el) => matches(el, selector)); }
    querySelector(selector) { return this.querySelectorAll(selector)[0] || null; }
    getElementsByTagName(name) { return descendants(this).filter((el) => name === '*' || el.localName === name.toLowerCase()); }
    getElementsByClassName(name) { return descendants(this).filter((el) => el.className.split(/\s+/).includes(name)); }
  }
  const document = new Document();
  // Builds the tree from the host's parse: [name, attributes, children] or a text string.
  const build = (parent, items) => {
    for (const item of items) {
      if (typeof item === 'string') { parent.appendChild(new Text(item)); continue; }
      const el = makeElement(item[0], item[1]);
      parent.appendChild(el);
      build(el, item[2]);
    }
  };

  // -- fetch and XMLHttpRequest over local files -------------------------------------------------
  class Response {
    constructor(url, text) { this.url = url; this.__text = text; this.ok = true; this.status = 200; }
    text() { return Promise.resolve(this.__text); }
    json() { return Promise.resolve(JSON.parse(this.__text)); }
    arrayBuffer() { return Promise.resolve(fromPython('uint8', this.__text).buffer); }
  }
  const localOnly = (url) => {
    if (/^(https?|data|blob|wss?):/i.test(String(url))) throw unsupported('network URLs (softgl.page loads local files only): ' + url);
  };
  const fetch = (url) => { localOnly(url); return new Promise((resolve, reject) => {
    setTimeout(() => {
      try { resolve(new Response(String(url), host.read_file(String(url), 'latin-1'))); } catch (e) { reject(e); }
    }, 0);
  }); };
  class XMLHttpRequest extends EventTarget {
    constructor() { super(); this.readyState = 0; this.status = 0; this.responseType = ''; this.response = null; this.responseText = ''; }
    open(method, url, async) {
      if (String(method).toUpperCase() !== 'GET') throw unsupported('XMLHttpRequest ' + method);
      localOnly(url);
      this.__url = String(url); this.__async = async !== false; this.readyState = 1;
    }
    overrideMimeType() {}
    setRequestHeader() {}
    send() {
      const finish = () => {
        const bytes = host.read_file(this.__url, 'latin-1');
        this.status = 200; this.readyState = 4;
        if (this.responseType === 'arraybuffer') this.response = fromPython('uint8', bytes).buffer;
        else {
          this.responseText = host.read_file(this.__url, 'utf-8');
          this.response = this.responseType === 'json' ? JSON.parse(this.responseText) : this.responseText;
        }
        if (typeof this.onreadystatechange === 'function') this.onreadystatechange();
        this.dispatchEvent(new Event('load'));
        this.dispatchEvent(new Event('loadend'));
      };
      if (this.__async) setTimeout(finish, 0); else finish();
    }
  }

  // -- console -----------------------------------------------------------------------------------
  const format = (x) => {
    if (typeof x === 'string') return x;
    if (x instanceof Error) return x.stack || String(x);
    try { const s = JSON.stringify(x); return s === undefined ? String(x) : s; } catch (e) { return String(x); }
  };
  const consoleObject = {};
  for (const level of ['log', 'info', 'warn', 'error', 'debug']) consoleObject[level] = (...args) => host.console(level, args.map(format));
  consoleObject.trace = consoleObject.debug;
  consoleObject.assert = (ok, ...args) => { if (!ok) host.console('error', ['Assertion failed:', ...args.map(format)]); };
  consoleObject.time = consoleObject.timeEnd = consoleObject.group = consoleObject.groupEnd = () => {};

  // -- window ------------------------------------------------------------------------------------
  const win = new EventTarget();
  const navigator = strict({ userAgent: 'softgl.page', platform: 'softgl', language: 'en', languages: ['en'],
    hardwareConcurrency: 1, maxTouchPoints: 0 }, 'navigator');
  const location = strict({ href: host.page_url, protocol: 'file:', host: '', hostname: '', pathname: host.page_url,
    search: '', hash: '', origin: 'null' }, 'location');
  Object.assign(win, {
    document, navigator, location, console: consoleObject, performance, fetch, XMLHttpRequest, Image: null,
    setTimeout, setInterval, clearTimeout, clearInterval: clearTimeout, requestAnimationFrame, cancelAnimationFrame,
    innerWidth: host.window_size[0], innerHeight: host.window_size[1], devicePixelRatio: 1,
    addEventListener: win.addEventListener.bind(win), removeEventListener: win.removeEventListener.bind(win),
    WebGLRenderingContext, WebGL2RenderingContext, HTMLCanvasElement, HTMLImageElement, HTMLElement: Element,
    Element, Node, Event, EventTarget: EventTarget, Response, ImageData, CanvasRenderingContext2D,
    alert: (msg) => host.console('alert', [format(msg)]),
    getComputedStyle: () => ({ getPropertyValue: () => '' }),
    matchMedia: () => ({ matches: false, addListener() {}, removeListener() {}, addEventListener() {}, removeEventListener() {} }),
  });
  for (const [name, cls] of Object.entries(glClasses)) win[name] = cls;
  win.Image = function Image(width, height) {
    const img = makeElement('img', {});
    if (width !== undefined) img.width = width;
    if (height !== undefined) img.height = height;
    return img;
  };
  win.window = win; win.self = win; win.globalThis = global;
  for (const key of Object.keys(win)) if (!(key in global) || key === 'console') global[key] = win[key];
  global.window = strict(win, 'window');
  global.self = global.window;
  global.document = strict(document, 'document');

  // The host's handles on this world.
  host.attach({
    buildJSON: (text) => { build(document, JSON.parse(text)); },
    json: (text) => JSON.parse(text),
    runScript: (source, name) => { try { (0, eval)(source + '\n//# sourceURL=' + name); } catch (e) { report(e); } },
    runHandler: (source, name) => {
      try { (0, eval)('(function (event) {' + source + '\n})//# sourceURL=' + name).call(global.window, new Event('load')); } catch (e) { report(e); }
    },
    fire: (target, type) => {
      const t = target === 'document' ? document : win;
      document.readyState = type === 'DOMContentLoaded' ? 'interactive' : 'complete';
      t.dispatchEvent(new Event(type));
    },
    runTimers, runFrame,
    pendingFrames: () => frameCallbacks.size,
    pendingTimers: () => timers.size,
    wrapHandle,
    fromPython,
    stackOf: (e) => (e && e.stack) ? String(e.stack) : String(e),
    lastStack: () => lastStack,
    clearLastStack: () => { lastStack = ''; },
  });
})(globalThis, __softgl_host);
