"""Shaders of our own that exercise what the course notes' shaders use, executed and compared
with float64 NumPy evaluations of the same formulas."""
import numpy as np

from conftest import compile_ok, run
from softgl import _core

rng = np.random.default_rng(1)


def test_constant_color():
    fs = """precision mediump float;
    uniform vec4 uMaterialDiffuse;
    void main() { gl_FragColor = uMaterialDiffuse; }"""
    r = compile_ok(fs, "fragment", 1)
    assert r["output_depends_only_on_uniforms"]
    out = run(fs, "fragment", uniforms={"uMaterialDiffuse": [0.1, 0.2, 0.3, 0.4]}, lanes=8, version=1)
    np.testing.assert_array_equal(out["gl_FragColor"], np.tile(np.float32([0.1, 0.2, 0.3, 0.4]), (8, 1)))


def test_per_vertex_color_pair():
    vs = """attribute vec4 vPosition;
    attribute vec4 vColor;
    uniform mat4 modelViewMatrix;
    uniform mat4 projectionMatrix;
    varying vec4 fColor;
    void main() {
        gl_Position = projectionMatrix * modelViewMatrix * vPosition;
        fColor = vColor;
    }"""
    fs = """precision mediump float;
    varying vec4 fColor;
    void main() { gl_FragColor = fColor; }"""
    ok, log, prog = _core.glsl_link(vs, fs, 1)
    assert ok, log
    assert [v["name"] for v in prog["varyings"]] == ["fColor"]
    assert sorted(a["name"] for a in prog["attributes"]) == ["vColor", "vPosition"]
    n = 16
    pos = rng.normal(size=(n, 4))
    col = rng.random((n, 4))
    mv = rng.normal(size=(4, 4))
    pr = rng.normal(size=(4, 4))
    out = run(vs, "vertex", {"vPosition": pos, "vColor": col},
              {"modelViewMatrix": mv.T.ravel(), "projectionMatrix": pr.T.ravel()}, lanes=n, version=1)
    expected = (pr.astype(np.float32).astype(np.float64) @ mv.astype(np.float32) @ pos.astype(np.float32).T).T
    np.testing.assert_allclose(out["gl_Position"], expected, rtol=1e-5, atol=1e-5)
    np.testing.assert_array_equal(out["fColor"], col.astype(np.float32))


def test_lambert_vertex_shader():
    vs = """attribute vec3 aPos;
    attribute vec3 aNormal;
    uniform mat4 uMVP;
    uniform mat3 uNormalMatrix;
    uniform vec3 uLightDirection;
    uniform vec4 uLightDiffuse;
    uniform vec4 uMaterialDiffuse;
    varying vec4 vColor;
    void main() {
        vec3 N = normalize(uNormalMatrix * aNormal);
        vec3 L = normalize(uLightDirection);
        float lambertTerm = max(dot(N, -L), 0.0);
        vColor = uMaterialDiffuse * uLightDiffuse * lambertTerm;
        vColor.a = 1.0;
        gl_Position = uMVP * vec4(aPos, 1.0);
    }"""
    n = 32
    normals = rng.normal(size=(n, 3))
    nm = rng.normal(size=(3, 3))
    light = np.array([0.3, -1.0, -0.2])
    ld = np.array([1.0, 0.9, 0.8, 1.0])
    md = np.array([0.5, 0.6, 0.7, 1.0])
    out = run(vs, "vertex", {"aPos": rng.normal(size=(n, 3)), "aNormal": normals},
              {"uMVP": np.eye(4).ravel(), "uNormalMatrix": nm.T.ravel(), "uLightDirection": light,
               "uLightDiffuse": ld, "uMaterialDiffuse": md}, lanes=n, version=1)
    N = normals @ nm.T
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    L = light / np.linalg.norm(light)
    lam = np.maximum(N @ -L, 0.0)
    expected = (md * ld)[None, :] * lam[:, None]
    expected[:, 3] = 1.0
    np.testing.assert_allclose(out["vColor"], expected, rtol=1e-5, atol=1e-6)


SPOT_VS = """#version 300 es
const int numLights = 3;
uniform mat4 uModelViewMatrix;
uniform mat4 uNormalMatrix;
uniform mat4 uProjectionMatrix;
uniform vec3 uLightPositions[numLights];
uniform vec3 uLightDirections[numLights];
in vec3 aPos;
in vec3 aNormal;
out vec3 vRay[numLights];
out vec3 vTransformedNormals[numLights];
void main(void) {
  vec4 vertex = uModelViewMatrix * vec4(aPos, 1.0);
  vec3 normal = vec3(uNormalMatrix * vec4(aNormal, 1.0));
  for (int i = 0; i < numLights; i++) {
    vec4 lightPosition = uModelViewMatrix * vec4(uLightPositions[i], 1.0);
    vRay[i] = vertex.xyz - lightPosition.xyz;
    vec3 directionLight = vec3(uNormalMatrix * vec4(uLightDirections[i], 1.0));
    vTransformedNormals[i] = normal - directionLight;
  }
  gl_Position = uProjectionMatrix * vertex;
}"""

SPOT_FS = """#version 300 es
precision mediump float;
const int numLights = 3;
uniform vec4 uLightColors[numLights];
uniform vec4 uMaterialAmbient;
uniform vec4 uMaterialDiffuse;
uniform vec4 uLightAmbient;
uniform float uLightCutOff;
in vec3 vRay[numLights];
in vec3 vTransformedNormals[numLights];
out vec4 fragColor;
void main(void) {
  vec4 Ia = uLightAmbient * uMaterialAmbient;
  vec4 Id = vec4(0.0);
  for (int i = 0; i < numLights; i++) {
    vec3 N = normalize(vTransformedNormals[i]);
    vec3 L = normalize(vRay[i]);
    float lambertTerm = dot(N, -L);
    if (lambertTerm > uLightCutOff) {
      Id += uLightColors[i] * uMaterialDiffuse * pow(lambertTerm, 10.0 * uLightCutOff);
    }
  }
  fragColor = vec4(vec3(Ia + Id), 1.0);
}"""


def test_three_spotlights_link_and_reflection():
    ok, log, prog = _core.glsl_link(SPOT_VS, SPOT_FS, 2)
    assert ok, log
    names = {u["name"] for u in prog["uniforms"] if u["active"]}
    assert {"uLightPositions[0]", "uLightDirections[0]", "uLightColors[0]", "uLightCutOff"} <= names
    sizes = {u["name"]: u["size"] for u in prog["uniforms"]}
    assert sizes["uLightColors[0]"] == 3
    assert {v["name"]: v["components"] for v in prog["varyings"]} == {"vRay": 9, "vTransformedNormals": 9}


def test_three_spotlights_values():
    n = 64
    mv = rng.normal(size=(4, 4)); nmat = rng.normal(size=(4, 4)); proj = rng.normal(size=(4, 4))
    lp = rng.normal(size=(3, 3)); ld = rng.normal(size=(3, 3))
    pos = rng.normal(size=(n, 3)); nor = rng.normal(size=(n, 3))
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
    out = run(SPOT_VS, "vertex", {"aPos": pos, "aNormal": nor},
              {"uModelViewMatrix": mv.T.ravel(), "uNormalMatrix": nmat.T.ravel(), "uProjectionMatrix": proj.T.ravel(),
               "uLightPositions": lp.ravel(), "uLightDirections": ld.ravel()}, lanes=n)
    h = lambda p: np.concatenate([f32(p), np.ones((len(p), 1))], axis=1)
    vertex = h(pos) @ f32(mv).T
    normal = (h(nor) @ f32(nmat).T)[:, :3]
    rays = np.stack([vertex[:, :3] - (h(lp[i:i + 1]) @ f32(mv).T)[:, :3] for i in range(3)], axis=1)
    tn = np.stack([normal - (h(ld[i:i + 1]) @ f32(nmat).T)[:, :3] for i in range(3)], axis=1)
    np.testing.assert_allclose(out["vRay"], rays.reshape(n, 9), rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(out["vTransformedNormals"], tn.reshape(n, 9), rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(out["gl_Position"], vertex @ f32(proj).T, rtol=1e-4, atol=1e-4)

    colors = rng.random((3, 4)); amb = rng.random(4); mamb = rng.random(4); mdif = rng.random(4)
    cutoff = 0.2
    fo = run(SPOT_FS, "fragment", {"vRay": out["vRay"], "vTransformedNormals": out["vTransformedNormals"]},
             {"uLightColors": colors.ravel(), "uMaterialAmbient": mamb, "uMaterialDiffuse": mdif,
              "uLightAmbient": amb, "uLightCutOff": cutoff}, lanes=n)
    R = f32(out["vRay"]).reshape(n, 3, 3); T = f32(out["vTransformedNormals"]).reshape(n, 3, 3)
    Id = np.zeros((n, 4))
    for i in range(3):
        N = T[:, i] / np.linalg.norm(T[:, i], axis=1, keepdims=True)
        L = R[:, i] / np.linalg.norm(R[:, i], axis=1, keepdims=True)
        lam = np.sum(N * -L, axis=1)
        lit = lam > np.float32(cutoff)
        term = f32(colors[i]) * f32(mdif) * np.where(lit, np.abs(lam), 1.0)[:, None] ** (10 * np.float32(cutoff))
        Id += np.where(lit[:, None], term, 0.0)
    expected = np.concatenate([(f32(amb) * f32(mamb))[None, :3] + Id[:, :3], np.ones((n, 1))], axis=1)
    np.testing.assert_allclose(fo["fragColor"], expected, rtol=2e-5, atol=2e-5)
    assert (R.shape[0] == n)


def test_points_only_vertex_shader_without_attributes():
    vs = """#version 300 es
    uniform float uPointSize;
    void main() {
        gl_PointSize = uPointSize * 2.0;
        gl_Position = vec4(float(gl_VertexID) * 0.1, 0.0, 0.0, 1.0);
    }"""
    r = compile_ok(vs, "vertex")
    assert r["writes_point_size"] and r["attributes"] == []
    out = run(vs, "vertex", {"gl_VertexID": np.arange(8)}, {"uPointSize": 5.0}, lanes=8)
    np.testing.assert_array_equal(out["gl_PointSize"][:, 0], np.full(8, 10.0, np.float32))
    np.testing.assert_allclose(out["gl_Position"][:, 0], np.arange(8) * np.float32(0.1), rtol=1e-7)

    vs1 = """void main() { gl_PointSize = 20.0; gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }"""
    out = run(vs1, "vertex", lanes=4, version=1)
    assert np.all(out["gl_PointSize"] == 20.0)


def checker(h, w):
    img = np.zeros((h, w, 4), np.float32)
    img[..., 0] = (np.arange(w)[None, :] % 2)
    img[..., 1] = (np.arange(h)[:, None] % 2)
    img[..., 3] = 1
    return img


def test_textured_shader():
    fs = """precision mediump float;
    varying vec2 fTexCoord;
    uniform sampler2D texMap;
    void main() { gl_FragColor = texture2D(texMap, fTexCoord); }"""
    r = compile_ok(fs, "fragment", 1)
    assert r["uses_derivatives"]
    assert [u["name"] for u in r["uniforms"] if u["active"]] == ["texMap"]
    tex = checker(4, 4)
    # texel centres sample exactly
    uv = np.array([[0.125, 0.125], [0.375, 0.125], [0.125, 0.375], [0.375, 0.375]], np.float32)
    out = run(fs, "fragment", {"fTexCoord": uv}, {"texMap": 0}, lanes=4, version=1, textures={0: tex})
    np.testing.assert_array_equal(out["gl_FragColor"], [[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1], [1, 1, 0, 1]])


def test_two_sampler_shader():
    fs = """#version 300 es
    precision mediump float;
    in vec2 vUV;
    uniform sampler2D uBase;
    uniform sampler2D uTint;
    uniform float uMix;
    out vec4 color;
    void main() { color = mix(texture(uBase, vUV), texture(uTint, vUV), uMix); }"""
    base = checker(4, 4)
    tint = np.zeros((1, 1, 4), np.float32); tint[0, 0] = [1, 0, 0, 1]
    uv = np.array([[0.125, 0.125], [0.375, 0.125], [0.125, 0.375], [0.375, 0.375]], np.float32)
    out = run(fs, "fragment", {"vUV": uv}, {"uBase": 0, "uTint": 1, "uMix": 0.25}, lanes=4, textures={0: base, 1: tint})
    b = base[[0, 0, 1, 1], [0, 1, 0, 1]].astype(np.float64)
    expected = b * (1 - 0.25) + np.array([1, 0, 0, 1]) * 0.25
    np.testing.assert_allclose(out["color"], expected, rtol=1e-6)


def test_shadow_visibility_shader():
    fs = """precision mediump float;
    varying vec4 vColor;
    uniform float visibility;
    void main() { gl_FragColor = vec4(vColor.rgb * visibility, vColor.a); }"""
    col = rng.random((8, 4)).astype(np.float32)
    for vis in (0.0, 1.0):
        out = run(fs, "fragment", {"vColor": col}, {"visibility": vis}, lanes=8, version=1)
        expected = col.copy(); expected[:, :3] *= np.float32(vis)
        np.testing.assert_array_equal(out["gl_FragColor"], expected)
