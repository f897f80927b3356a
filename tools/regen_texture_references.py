"""Regenerate tests/textures/reference/*.png from real WebGL in headless Chromium (SwiftShader).

    python tools/regen_texture_references.py        (needs `apt-get install chromium`)

multitexture_<filter>_webgl<version>.png: the course's multitexturing exercise
(tests/textures/multitexture_scene.py: three quads, one shader, a checkerboard on unit 0 and a 1x1 red
texture made from [255, 0, 0] on unit 1), drawn by Chromium with the same vertices, matrix and
texels as softgl; stored top row first (as images are).
"""
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "webgl"))
sys.path.insert(0, str(ROOT / "tests" / "textures"))
from chromium import chromium_version, run_script  # noqa: E402
import multitexture_scene as scenes  # noqa: E402

OUT = ROOT / "tests" / "textures" / "reference"

SCENE_JS = r"""
function compile(gl, type, src) {
  const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
function multitexture(version, minify) {
  const canvas = document.createElement('canvas');
  canvas.width = P.width; canvas.height = P.height;
  const gl = canvas.getContext(version == 1 ? 'webgl' : 'webgl2', {antialias: false, preserveDrawingBuffer: true});
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, P.vertex));
  gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, P.fragment));
  gl.linkProgram(prog);
  gl.useProgram(prog);
  gl.clearColor(0.3921, 0.5843, 0.9294, 1.0);
  gl.enable(gl.DEPTH_TEST);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(P.quads), gl.STATIC_DRAW);
  const pos = gl.getAttribLocation(prog, 'vPosition'), tex = gl.getAttribLocation(prog, 'vTexCoord');
  gl.vertexAttribPointer(pos, 4, gl.FLOAT, false, 24, 0); gl.enableVertexAttribArray(pos);
  gl.vertexAttribPointer(tex, 2, gl.FLOAT, false, 24, 16); gl.enableVertexAttribArray(tex);
  gl.uniformMatrix4fv(gl.getUniformLocation(prog, 'projection'), false, new Float32Array(P.projection));
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, P.checker_size, P.checker_size, 0, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(P.checker));
  gl.generateMipmap(gl.TEXTURE_2D);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.REPEAT);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, minify);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.activeTexture(gl.TEXTURE1);
  gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 1, 1, 0, gl.RGB, gl.UNSIGNED_BYTE, new Uint8Array([255, 0, 0]));
  const sampler = gl.getUniformLocation(prog, 'texMap');
  gl.uniform1i(sampler, 0);
  gl.drawArrays(gl.TRIANGLES, 0, 6);
  gl.uniform1i(sampler, 1);
  gl.drawArrays(gl.TRIANGLES, 6, 12);
  const px = new Uint8Array(P.width * P.height * 4);
  gl.readPixels(0, 0, P.width, P.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const err = gl.getError();
  gl.getExtension('WEBGL_lose_context').loseContext();
  return {error: err, pixels: Array.from(px)};
}
result = {};
for (const [name, minify] of Object.entries(P.filters))
  for (const version of [1, 2]) result[name + '_webgl' + version] = multitexture(version, minify);
"""

FILTERS = {"nearest": 0x2600, "linear_mipmap_linear": 0x2703}


def main():
    params = {
        "width": scenes.WIDTH, "height": scenes.HEIGHT, "vertex": scenes.VERTEX, "fragment": scenes.FRAGMENT,
        "quads": scenes.QUADS.ravel().tolist(),
        "projection": scenes.perspective(90, 1, 1, 25).T.astype(np.float32).ravel().tolist(),
        "checker": scenes.checkerboard().ravel().tolist(), "checker_size": scenes.CHECKER_SIZE,
        "filters": FILTERS,
    }
    result = run_script("const P = " + json.dumps(params) + ";\n" + SCENE_JS, timeout=300)
    import softgl.io
    OUT.mkdir(parents=True, exist_ok=True)
    for key, value in result.items():
        assert value["error"] == 0, (key, value["error"])
        img = np.array(value["pixels"], np.uint8).reshape(scenes.HEIGHT, scenes.WIDTH, 4)[::-1]
        softgl.io.save(np.ascontiguousarray(img), OUT / f"multitexture_{key}.png")
    (OUT / "chromium_version.txt").write_text(chromium_version() + "\n")
    print("wrote", sorted(result), "with", chromium_version())


if __name__ == "__main__":
    main()
