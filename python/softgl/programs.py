"""Building programs from GLSL sources in one call, and the stock shaders of the course.

``program(gl, vs, fs)`` compiles and links (raising ShaderError with the info log).
``Program`` wraps a linked program with its uniforms and attributes by name, so that
``prog.set(uMaterialDiffuse=(1, 0, 0, 1), uModel=translate(0, 1, 0))`` picks the right
``uniform*`` call for each uniform's type (matrices are given in math layout, (4, 4), and
uploaded column-major).

The stock programs (``constant_color``, ``vertex_color``, ``random_color``, ``lambert``,
``phong``, ``lights``) are GLSL ES 1.00, so they run in WebGL 1 and WebGL 2 contexts. They share
names, so a scene can drive any of them the same way:

=====================  ======================================================================
attributes             ``aPosition`` (vec3), ``aNormal`` (vec3), ``aColor`` (vec4)
transforms             ``uModel``, ``uView``, ``uProjection`` (mat4), ``uNormalMatrix`` (mat4:
                       inverse transpose of ``uView * uModel``, see transforms.normal_matrix)
material               ``uMaterialDiffuse`` (vec4; its alpha is the fragment's alpha),
                       ``uMaterialAmbient``, ``uMaterialSpecular`` (vec4), ``uShininess``
one directional light  ``uLightDirection`` (vec3, world space, the way the light travels),
                       ``uLightDiffuse``, ``uLightSpecular``, ``uLightAmbient`` (vec4)
N point/spot lights    ``uLightPositions[N]``, ``uLightDirections[N]`` (vec3, world space;
                       (0, 0, 0) for a point light), ``uLightColors[N]`` (vec4),
                       ``uLightCutoffs[N]`` (float), ``uLightAmbient``
output                 ``uVisibility`` (1: normal, 0: a black projected shadow; the color's
                       rgb is multiplied by it), ``uPremultiply`` (bool: output rgb * alpha,
                       for premultiplied blending), ``uPointSize``
=====================  ======================================================================

The textured programs add ``aTexCoord`` (vec2, the mesh's uvs) and samplers ``uTexture0`` /
``uTexture1`` (texture units, default 0 and 1) with ``uTexScale0`` / ``uTexScale1`` (vec2: how
many times each texture repeats). The fogged program and the GLSL snippets in ``FOG_GLSL`` fog in
the shader, as one does without softgl's SOFTGL_fog extension (see ``fog_factor`` for the same
formulas in float64).

Lighting is computed per fragment in eye space. The spot lights follow the course notes: the
normal is bent away from the light's direction, ``N' = normalize(N - D)`` with ``D`` as given
(not normalised, as in the lesson: its length sets how far the normal bends), the Lambert term is
``lambert = dot(N', -L)`` with ``L`` the ray from the light to the fragment, and a light
contributes ``color * diffuse * pow(lambert, 10 * cutoff)`` where ``lambert > cutoff``. A point
light (``D = 0``) contributes ``color * diffuse * lambert`` where ``lambert > cutoff``.
"""
from __future__ import annotations

import numpy as np

from .errors import GLError


class ShaderError(GLError):
    """A shader failed to compile or a program failed to link; the message is the info log."""

    def __init__(self, what: str, log: str):
        Exception.__init__(self, f"{what}:\n{log}")
        self.log = log


def program(gl, vertex_source: str, fragment_source: str, attribute_locations: dict | None = None):
    """Compile both shaders, link them (binding `attribute_locations` first) and return the
    WebGLProgram. Raises ShaderError with the info log on failure; leaves no GL error pending."""
    shaders = []
    for kind, source in ((gl.VERTEX_SHADER, vertex_source), (gl.FRAGMENT_SHADER, fragment_source)):
        shader = gl.createShader(kind)
        gl.shaderSource(shader, source)
        gl.compileShader(shader)
        if not gl.getShaderParameter(shader, gl.COMPILE_STATUS):
            log = gl.getShaderInfoLog(shader)
            gl.deleteShader(shader)
            for s in shaders:
                gl.deleteShader(s)
            raise ShaderError("vertex shader" if kind == gl.VERTEX_SHADER else "fragment shader", log)
        shaders.append(shader)
    prog = gl.createProgram()
    for shader in shaders:
        gl.attachShader(prog, shader)
    for name, location in (attribute_locations or {}).items():
        gl.bindAttribLocation(prog, location, name)
    gl.linkProgram(prog)
    for shader in shaders:
        gl.deleteShader(shader)   # freed with the program
    if not gl.getProgramParameter(prog, gl.LINK_STATUS):
        log = gl.getProgramInfoLog(prog)
        gl.deleteProgram(prog)
        raise ShaderError("link", log)
    return prog


# -- Program: a linked program with its uniforms by name ----------------------------------------

def _uniform_setters(gl) -> dict:
    """uniform type -> (setter name, components per element)."""
    table = {"FLOAT": ("uniform1fv", 1), "FLOAT_VEC2": ("uniform2fv", 2),
             "FLOAT_VEC3": ("uniform3fv", 3), "FLOAT_VEC4": ("uniform4fv", 4),
             "INT": ("uniform1iv", 1), "INT_VEC2": ("uniform2iv", 2),
             "INT_VEC3": ("uniform3iv", 3), "INT_VEC4": ("uniform4iv", 4),
             "BOOL": ("uniform1iv", 1), "BOOL_VEC2": ("uniform2iv", 2),
             "BOOL_VEC3": ("uniform3iv", 3), "BOOL_VEC4": ("uniform4iv", 4),
             "UNSIGNED_INT": ("uniform1uiv", 1), "UNSIGNED_INT_VEC2": ("uniform2uiv", 2),
             "UNSIGNED_INT_VEC3": ("uniform3uiv", 3), "UNSIGNED_INT_VEC4": ("uniform4uiv", 4),
             "FLOAT_MAT2": ("uniformMatrix2fv", 4), "FLOAT_MAT3": ("uniformMatrix3fv", 9),
             "FLOAT_MAT4": ("uniformMatrix4fv", 16)}
    setters = {getattr(gl, name): value for name, value in table.items() if hasattr(gl, name)}
    for name in ("SAMPLER_2D", "SAMPLER_CUBE", "SAMPLER_3D", "SAMPLER_2D_ARRAY", "SAMPLER_2D_SHADOW"):
        if hasattr(gl, name):
            setters[getattr(gl, name)] = ("uniform1iv", 1)
    return setters


class Program:
    """A linked WebGLProgram with its active uniforms and attributes by name.

    ``Program(gl, vs, fs, defaults={...})`` compiles, links and sets `defaults`.
    ``prog.set(name=value, ...)`` uses the program and uploads each value with the call its type
    needs. Names the program does not use (never declared, or optimised away) are skipped, as
    WebGL skips a ``None`` location. Square matrices may be given as (n, n) arrays in math
    layout (transposed for WebGL) or as n*n floats already column-major; arrays of uniforms
    take all their elements at once (``uLightColors=[[1, 0, 0, 1], [0, 1, 0, 1]]``).
    """

    def __init__(self, gl, vertex_source: str, fragment_source: str, defaults: dict | None = None,
                 name: str = "program"):
        self.gl = gl
        self.name = name
        self.vertex_source = vertex_source
        self.fragment_source = fragment_source
        self.handle = program(gl, vertex_source, fragment_source)
        self.uniforms = {}      # base name -> (location, type, array size)
        for i in range(gl.getProgramParameter(self.handle, gl.ACTIVE_UNIFORMS)):
            info = gl.getActiveUniform(self.handle, i)
            base = info.name[:-3] if info.name.endswith("[0]") else info.name
            self.uniforms[base] = (gl.getUniformLocation(self.handle, info.name), info.type, info.size)
        self.attributes = {}    # name -> location
        for i in range(gl.getProgramParameter(self.handle, gl.ACTIVE_ATTRIBUTES)):
            info = gl.getActiveAttrib(self.handle, i)
            self.attributes[info.name] = gl.getAttribLocation(self.handle, info.name)
        self._setters = _uniform_setters(gl)
        if defaults:
            self.set(**defaults)

    def use(self):
        self.gl.useProgram(self.handle)
        return self

    def __contains__(self, uniform_name: str) -> bool:
        return uniform_name in self.uniforms

    def set(self, **values):
        """Upload uniforms by name (see the class docstring); returns self."""
        self.gl.useProgram(self.handle)
        for name, value in values.items():
            if name not in self.uniforms:
                continue
            location, kind, size = self.uniforms[name]
            setter, per_element = self._setters[kind]
            data = np.asarray(value, np.float64)
            if setter.startswith("uniformMatrix"):
                n = {4: 2, 9: 3, 16: 4}[per_element]
                if data.shape[-2:] == (n, n):   # math layout -> column-major
                    data = np.swapaxes(data, -1, -2)
            flat = data.reshape(-1)
            if len(flat) % per_element or not 0 < len(flat) // per_element <= size:
                raise ValueError(f"{self.name}: uniform {name} takes {size} x {per_element} "
                                 f"values, got {data.shape}")
            if setter.startswith("uniformMatrix"):
                getattr(self.gl, setter)(location, False, flat.astype(np.float32))
            elif setter.endswith("uiv"):
                getattr(self.gl, setter)(location, flat.astype(np.uint32))
            elif setter.endswith("iv"):
                getattr(self.gl, setter)(location, flat.astype(np.int32))
            else:
                getattr(self.gl, setter)(location, flat.astype(np.float32))
        return self

    def __repr__(self):
        return f"<softgl.programs.Program {self.name}: uniforms {sorted(self.uniforms)}>"


# -- The stock shaders --------------------------------------------------------------------------

_HEADER = "precision highp float;\n"

_VERTEX = """
attribute vec3 aPosition;
attribute vec3 aNormal;
attribute vec4 aColor;
uniform mat4 uModel;
uniform mat4 uView;
uniform mat4 uProjection;
uniform mat4 uNormalMatrix;
uniform float uPointSize;
varying vec3 vEyePosition;
varying vec3 vEyeNormal;
varying vec4 vColor;
void main() {
    vec4 eye = uView * uModel * vec4(aPosition, 1.0);
    vEyePosition = eye.xyz;
    vEyeNormal = (uNormalMatrix * vec4(aNormal, 0.0)).xyz;
    vColor = aColor;
    gl_Position = uProjection * eye;
    gl_PointSize = uPointSize;
}
"""

_OUTPUT = """
uniform float uVisibility;
uniform bool uPremultiply;
vec4 finish(vec4 color) {
    color.rgb *= uVisibility;
    if (uPremultiply) color.rgb *= color.a;
    return color;
}
"""

_CONSTANT = """
uniform vec4 uMaterialDiffuse;
void main() { gl_FragColor = finish(uMaterialDiffuse); }
"""

_PER_VERTEX = """
varying vec4 vColor;
void main() { gl_FragColor = finish(vColor); }
"""

# A permutation polynomial (mod 289) of the fragment's integer window position: every step is
# exact in float32, so the colors are the same on every machine and easy to recompute.
_RANDOM = """
uniform vec4 uMaterialDiffuse;
uniform float uSeed;
float permute(float x) { return mod((34.0 * x + 1.0) * x, 289.0); }
void main() {
    vec2 p = mod(floor(gl_FragCoord.xy), 289.0);
    float r = permute(permute(p.x + mod(uSeed, 289.0)) + p.y);
    float g = permute(permute(p.y + mod(uSeed + 97.0, 289.0)) + p.x);
    float b = permute(r + g);
    gl_FragColor = finish(vec4(vec3(r, g, b) / 288.0, uMaterialDiffuse.a));
}
"""

_LAMBERT = """
uniform mat4 uView;
uniform vec3 uLightDirection;
uniform vec4 uLightDiffuse;
uniform vec4 uLightAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uMaterialAmbient;
varying vec3 vEyeNormal;
void main() {
    vec3 N = normalize(vEyeNormal);
    vec3 L = normalize((uView * vec4(uLightDirection, 0.0)).xyz);
    float lambert = max(dot(N, -L), 0.0);
    vec4 color = uLightAmbient * uMaterialAmbient + uLightDiffuse * uMaterialDiffuse * lambert;
    gl_FragColor = finish(vec4(color.rgb, uMaterialDiffuse.a));
}
"""

_PHONG = """
uniform mat4 uView;
uniform vec3 uLightDirection;
uniform vec4 uLightDiffuse;
uniform vec4 uLightSpecular;
uniform vec4 uLightAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uMaterialAmbient;
uniform vec4 uMaterialSpecular;
uniform float uShininess;
varying vec3 vEyePosition;
varying vec3 vEyeNormal;
void main() {
    vec3 N = normalize(vEyeNormal);
    vec3 L = normalize((uView * vec4(uLightDirection, 0.0)).xyz);
    float lambert = max(dot(N, -L), 0.0);
    vec4 color = uLightAmbient * uMaterialAmbient + uLightDiffuse * uMaterialDiffuse * lambert;
    if (lambert > 0.0) {
        vec3 R = reflect(L, N);
        vec3 E = normalize(-vEyePosition);
        color += uLightSpecular * uMaterialSpecular * pow(max(dot(R, E), 0.0), uShininess);
    }
    gl_FragColor = finish(vec4(color.rgb, uMaterialDiffuse.a));
}
"""

_LIGHTS = """
const int NUM_LIGHTS = {n};
uniform mat4 uView;
uniform vec3 uLightPositions[NUM_LIGHTS];
uniform vec3 uLightDirections[NUM_LIGHTS];
uniform vec4 uLightColors[NUM_LIGHTS];
uniform float uLightCutoffs[NUM_LIGHTS];
uniform vec4 uLightAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uMaterialAmbient;
varying vec3 vEyePosition;
varying vec3 vEyeNormal;
void main() {
    vec3 normal = normalize(vEyeNormal);
    vec4 Id = vec4(0.0);
    for (int i = 0; i < NUM_LIGHTS; i++) {
        vec3 lightPosition = (uView * vec4(uLightPositions[i], 1.0)).xyz;
        vec3 D = (uView * vec4(uLightDirections[i], 0.0)).xyz;
        bool spot = dot(D, D) > 0.0;
        vec3 N = spot ? normalize(normal - D) : normal;
        vec3 L = normalize(vEyePosition - lightPosition);
        float lambert = dot(N, -L);
        if (lambert > uLightCutoffs[i]) {
            float f = spot ? pow(lambert, 10.0 * uLightCutoffs[i]) : lambert;
            Id += uLightColors[i] * uMaterialDiffuse * f;
        }
    }
    vec4 color = uLightAmbient * uMaterialAmbient + Id;
    gl_FragColor = finish(vec4(color.rgb, uMaterialDiffuse.a));
}
"""

_VERTEX_TEXTURED = _VERTEX.replace(
    "attribute vec4 aColor;", "attribute vec4 aColor;\nattribute vec2 aTexCoord;\nvarying vec2 vTexCoord;"
).replace("vColor = aColor;", "vColor = aColor;\n    vTexCoord = aTexCoord;")

_TEXTURED = """
uniform sampler2D uTexture0;
uniform vec2 uTexScale0;
uniform vec4 uMaterialDiffuse;
varying vec2 vTexCoord;
void main() { gl_FragColor = finish(texture2D(uTexture0, vTexCoord * uTexScale0) * uMaterialDiffuse); }
"""

# uCombine: 0 modulate (t0 * t1), 1 add (t0 + t1, clamped), 2 interpolate (mix(t0, t1, uMix)),
# 3 decal (t1 over t0 by t1's alpha; the alpha is t0's).
MULTITEXTURE_COMBINE = {"modulate": 0, "add": 1, "interpolate": 2, "decal": 3}
_MULTITEXTURED = """
uniform sampler2D uTexture0;
uniform sampler2D uTexture1;
uniform vec2 uTexScale0;
uniform vec2 uTexScale1;
uniform int uCombine;
uniform float uMix;
uniform vec4 uMaterialDiffuse;
varying vec2 vTexCoord;
void main() {
    vec4 t0 = texture2D(uTexture0, vTexCoord * uTexScale0);
    vec4 t1 = texture2D(uTexture1, vTexCoord * uTexScale1);
    vec4 c;
    if (uCombine == 0) c = t0 * t1;
    else if (uCombine == 1) c = min(t0 + t1, vec4(1.0));
    else if (uCombine == 2) c = mix(t0, t1, uMix);
    else c = vec4(mix(t0.rgb, t1.rgb, t1.a), t0.a);
    gl_FragColor = finish(c * uMaterialDiffuse);
}
"""

# Fog in GLSL (the OpenGL 1.x formulas, GL 1.5 §3.10): f is the fraction of the fragment's own
# color that remains, c the fog coordinate (the eye distance).
FOG_GLSL = """
float fogLinear(float c, float start, float end) { return clamp((end - c) / (end - start), 0.0, 1.0); }
float fogExp(float c, float density) { return clamp(exp(-density * c), 0.0, 1.0); }
float fogExp2(float c, float density) { float d = density * c; return clamp(exp(-d * d), 0.0, 1.0); }
vec3 applyFog(vec3 color, vec3 fogColor, float f) { return mix(fogColor, color, f); }
"""
FOG_MODES = {"LINEAR": 0, "EXP": 1, "EXP2": 2}

# Lambert light, then fog. uFogCoordinate 0: the eye depth -z (what SOFTGL_fog's FRAGMENT_DEPTH
# and OpenGL's usual approximation use), 1: the radial distance |eye position|.
_FOGGED = FOG_GLSL + """
uniform mat4 uView;
uniform vec3 uLightDirection;
uniform vec4 uLightDiffuse;
uniform vec4 uLightAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uMaterialAmbient;
uniform bool uLit;
uniform int uFogMode;
uniform int uFogCoordinate;
uniform float uFogDensity;
uniform float uFogStart;
uniform float uFogEnd;
uniform vec4 uFogColor;
varying vec3 vEyePosition;
varying vec3 vEyeNormal;
void main() {
    vec4 color = uMaterialDiffuse;
    if (uLit) {
        vec3 N = normalize(vEyeNormal);
        vec3 L = normalize((uView * vec4(uLightDirection, 0.0)).xyz);
        float lambert = max(dot(N, -L), 0.0);
        color = vec4((uLightAmbient * uMaterialAmbient + uLightDiffuse * uMaterialDiffuse * lambert).rgb,
                     uMaterialDiffuse.a);
    }
    float c = uFogCoordinate == 0 ? -vEyePosition.z : length(vEyePosition);
    float f = uFogMode == 0 ? fogLinear(c, uFogStart, uFogEnd)
            : uFogMode == 1 ? fogExp(c, uFogDensity) : fogExp2(c, uFogDensity);
    gl_FragColor = finish(vec4(applyFog(color.rgb, uFogColor.rgb, f), color.a));
}
"""

_IDENTITY = np.eye(4)
COMMON_DEFAULTS = dict(uModel=_IDENTITY, uView=_IDENTITY, uProjection=_IDENTITY,
                       uNormalMatrix=_IDENTITY, uPointSize=1.0, uVisibility=1.0,
                       uPremultiply=0, uMaterialDiffuse=(1.0, 1.0, 1.0, 1.0),
                       uMaterialAmbient=(1.0, 1.0, 1.0, 1.0), uLightAmbient=(0.1, 0.1, 0.1, 1.0))
LIGHT_DEFAULTS = dict(uLightDirection=(0.0, -1.0, -1.0), uLightDiffuse=(1.0, 1.0, 1.0, 1.0),
                      uLightSpecular=(1.0, 1.0, 1.0, 1.0), uMaterialSpecular=(1.0, 1.0, 1.0, 1.0),
                      uShininess=32.0)


def _stock(gl, name: str, fragment_body: str, defaults: dict | None = None,
           vertex: str = _VERTEX) -> Program:
    return Program(gl, vertex, _HEADER + _OUTPUT + fragment_body,
                   {**COMMON_DEFAULTS, **LIGHT_DEFAULTS, **(defaults or {})}, name=name)


def constant_color(gl) -> Program:
    """Every fragment is ``uMaterialDiffuse``."""
    return _stock(gl, "constant_color", _CONSTANT)


def vertex_color(gl) -> Program:
    """The ``aColor`` attribute, interpolated across each primitive."""
    return _stock(gl, "vertex_color", _PER_VERTEX)


def random_color(gl, seed: int = 0) -> Program:
    """A pseudo-random color per pixel (from its window position and ``uSeed``); the alpha is
    ``uMaterialDiffuse.a``. See ``random_color_reference`` for the same colors in NumPy."""
    return _stock(gl, "random_color", _RANDOM, {"uSeed": float(seed)})


def lambert(gl) -> Program:
    """Ambient plus diffuse (Lambert) light from one directional light."""
    return _stock(gl, "lambert", _LAMBERT)


def phong(gl) -> Program:
    """Lambert plus a Phong specular highlight (``pow(max(R.E, 0), uShininess)``)."""
    return _stock(gl, "phong", _PHONG)


def lights(gl, count: int = 3) -> Program:
    """`count` point and spot lights through uniform arrays, as in the course notes (see the
    module docstring for the formula). Lights default to off (black)."""
    if not isinstance(count, int) or count < 1:
        raise ValueError("lights: count must be a positive int")
    defaults = {"uLightPositions": np.zeros((count, 3)), "uLightDirections": np.zeros((count, 3)),
                "uLightColors": np.zeros((count, 4)), "uLightCutoffs": np.zeros(count)}
    return _stock(gl, f"lights({count})", _LIGHTS.replace("{n}", str(count)), defaults)


def textured(gl) -> Program:
    """``texture2D(uTexture0, vTexCoord * uTexScale0) * uMaterialDiffuse`` (unit 0, unlit)."""
    return _stock(gl, "textured", _TEXTURED, {"uTexture0": 0, "uTexScale0": (1.0, 1.0)},
                  vertex=_VERTEX_TEXTURED)


def multitextured(gl, combine: str = "modulate") -> Program:
    """Two samplers, ``uTexture0`` (unit 0) and ``uTexture1`` (unit 1), combined by `combine`
    (see MULTITEXTURE_COMBINE; change it later with ``uCombine``), times ``uMaterialDiffuse``."""
    if combine not in MULTITEXTURE_COMBINE:
        raise ValueError(f"multitextured: combine is one of {sorted(MULTITEXTURE_COMBINE)}")
    return _stock(gl, "multitextured", _MULTITEXTURED,
                  {"uTexture0": 0, "uTexture1": 1, "uTexScale0": (1.0, 1.0), "uTexScale1": (1.0, 1.0),
                   "uCombine": MULTITEXTURE_COMBINE[combine], "uMix": 0.5}, vertex=_VERTEX_TEXTURED)


def fogged(gl, mode: str = "EXP", density: float = 1.0, start: float = 0.0, end: float = 1.0,
           color=(0.5, 0.5, 0.5, 1.0), lit: bool = True, radial: bool = False) -> Program:
    """Lambert light (or the plain ``uMaterialDiffuse`` when `lit` is False), then fog computed
    in the fragment shader with the FOG_GLSL functions: ``uFogMode`` (FOG_MODES), ``uFogDensity``,
    ``uFogStart``, ``uFogEnd``, ``uFogColor``; the coordinate is the eye depth -z, or the radial
    distance when `radial`."""
    if mode not in FOG_MODES:
        raise ValueError(f"fogged: mode is one of {sorted(FOG_MODES)}")
    return _stock(gl, f"fogged({mode})", _FOGGED,
                  {"uFogMode": FOG_MODES[mode], "uFogDensity": density, "uFogStart": start,
                   "uFogEnd": end, "uFogColor": color, "uLit": int(lit),
                   "uFogCoordinate": int(radial)})


def fog_factor(mode: str, c, density: float = 1.0, start: float = 0.0, end: float = 1.0) -> np.ndarray:
    """The fog factor f (the fraction of the fragment's color that remains) in float64 for fog
    coordinates `c`: LINEAR (end - c) / (end - start), EXP exp(-density c), EXP2
    exp(-(density c)^2), clamped to [0, 1] (GL 1.5 §3.10)."""
    c = np.asarray(c, np.float64)
    if mode == "LINEAR":
        f = (end - c) / (end - start)
    elif mode == "EXP":
        f = np.exp(-density * c)
    elif mode == "EXP2":
        f = np.exp(-(density * c) ** 2)
    else:
        raise ValueError(f"fog_factor: mode is one of {sorted(FOG_MODES)}")
    return np.clip(f, 0.0, 1.0)


STOCK = {"constant": constant_color, "vertex": vertex_color, "random": random_color,
         "lambert": lambert, "phong": phong, "lights": lights, "textured": textured,
         "multitextured": multitextured, "fogged": fogged}


def random_color_reference(x, y, seed: float = 0.0) -> np.ndarray:
    """The colors ``random_color`` gives the pixels at window positions (x, y) (integers,
    row 0 at the bottom), as float64 RGB in [0, 1]."""
    def permute(v):
        return np.mod((34.0 * v + 1.0) * v, 289.0)
    px, py = np.mod(np.asarray(x, np.float64), 289.0), np.mod(np.asarray(y, np.float64), 289.0)
    r = permute(permute(px + np.mod(seed, 289.0)) + py)
    g = permute(permute(py + np.mod(seed + 97.0, 289.0)) + px)
    b = permute(r + g)
    return np.stack([r, g, b], axis=-1) / 288.0
