"""Regenerate tests/pipeline/reference/coverage_chromium.json: coverage of single primitives in real
WebGL (headless Chromium + SwiftShader), for the rasterizer's tie-rule and point/line tests.

    python tools/regen_raster_references.py      (needs `apt-get install chromium`)

Every case is drawn alone on a cleared 16x16 target (WebGL 2, antialias:false) with a constant
white fragment shader, both into the default framebuffer and into an RGBA8 framebuffer object, and
read back with readPixels. Coverage is stored as one integer bitmask per row (bit x = pixel x, row 0 =
bottom, as GL). Vertices are given in window coordinates on a 1/16-pixel grid so that any rasterizer
with >= 4 sub-pixel bits snaps them exactly (SwiftShader uses 4, softgl 8).
"""
import json
import random
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "webgl"))
from chromium import chromium_version, run_script  # noqa: E402

OUT = ROOT / "tests" / "pipeline" / "reference" / "coverage_chromium.json"
SIZE = 16


def triangle_cases():
    cases = []
    # Edges exactly through pixel centres: axis-aligned right triangles in all 4 corners, both windings.
    for (a, b, c) in [((4.5, 4.5), (10.5, 4.5), (4.5, 10.5)),
                      ((10.5, 4.5), (10.5, 10.5), (4.5, 10.5)),
                      ((4.5, 4.5), (10.5, 4.5), (10.5, 10.5)),
                      ((4.5, 4.5), (10.5, 10.5), (4.5, 10.5)),
                      ((2.5, 2.5), (13.5, 2.5), (8.0, 13.5)),
                      ((2.5, 13.5), (8.0, 2.5), (13.5, 13.5)),
                      ((2.5, 2.5), (13.5, 8.0), (2.5, 13.5)),
                      ((13.5, 2.5), (13.5, 13.5), (2.5, 8.0)),
                      ((3.0, 3.0), (13.0, 3.0), (3.0, 13.0)),
                      ((1.5, 1.5), (14.5, 1.5), (1.5, 14.5))]:
        cases.append([a, b, c])
        cases.append([a, c, b])
    rng = random.Random(4)
    # Vertices at pixel centres (many shared-vertex and on-edge ties).
    for _ in range(40):
        cases.append([(rng.randrange(0, 16) + 0.5, rng.randrange(0, 16) + 0.5) for _ in range(3)])
    # Vertices on a half-pixel grid (edges through centres at many slopes).
    for _ in range(40):
        cases.append([(rng.randrange(0, 33) / 2, rng.randrange(0, 33) / 2) for _ in range(3)])
    # Vertices on the 1/16 grid.
    for _ in range(40):
        cases.append([(rng.randrange(0, 257) / 16, rng.randrange(0, 257) / 16) for _ in range(3)])
    return cases


def point_cases():
    rng = random.Random(5)
    cases = [[8.0, 8.0, s] for s in (1, 2, 3, 4, 5)]
    cases += [[8.5, 8.5, s] for s in (1, 2, 3, 4, 5)]
    for _ in range(30):
        cases.append([rng.randrange(0, 257) / 16, rng.randrange(0, 257) / 16, rng.randrange(1, 7)])
    cases += [[0.5, 8.0, 6], [15.75, 15.75, 7], [-1.0, 4.0, 5]]   # partly off-screen
    return cases


def line_cases():
    rng = random.Random(6)
    cases = [[(2.5, 2.5), (13.5, 2.5)], [(2.5, 2.5), (2.5, 13.5)], [(2.5, 2.5), (13.5, 13.5)],
             [(2.0, 2.0), (14.0, 6.0)], [(13.5, 3.0), (3.0, 12.5)], [(2.0, 8.0), (14.0, 8.0)]]
    for _ in range(30):
        cases.append([(rng.randrange(0, 257) / 16, rng.randrange(0, 257) / 16) for _ in range(2)])
    return cases


JS = r"""
const S = %(size)d, cases = %(cases)s;
const canvas = document.createElement('canvas'); canvas.width = S; canvas.height = S;
const gl = canvas.getContext('webgl2', {antialias: false, preserveDrawingBuffer: true});
function sh(type, src) { const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s); return s; }
const prog = gl.createProgram();
gl.attachShader(prog, sh(gl.VERTEX_SHADER, `#version 300 es
in vec2 p; in float size;
void main() { gl_Position = vec4(p, 0.0, 1.0); gl_PointSize = size; }`));
gl.attachShader(prog, sh(gl.FRAGMENT_SHADER, `#version 300 es
precision mediump float; out vec4 c; void main() { c = vec4(1.0); }`));
gl.bindAttribLocation(prog, 0, 'p'); gl.bindAttribLocation(prog, 1, 'size');
gl.linkProgram(prog); gl.useProgram(prog);
const buf = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf);
gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
const tex = gl.createTexture(); gl.bindTexture(gl.TEXTURE_2D, tex);
gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, S, S, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
const fbo = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
function ndc(v) { return [2 * v[0] / S - 1, 2 * v[1] / S - 1]; }
function draw(target, mode, verts, size) {
  gl.bindFramebuffer(gl.FRAMEBUFFER, target);
  gl.viewport(0, 0, S, S); gl.clearColor(0, 0, 0, 0); gl.clear(gl.COLOR_BUFFER_BIT);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(verts.flatMap(ndc)), gl.STREAM_DRAW);
  gl.vertexAttrib1f(1, size);
  gl.drawArrays(mode, 0, verts.length);
  const px = new Uint8Array(S * S * 4); gl.readPixels(0, 0, S, S, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const rows = [];
  for (let y = 0; y < S; y++) { let m = 0; for (let x = 0; x < S; x++) if (px[(y * S + x) * 4] > 127) m |= 1 << x; rows.push(m); }
  return rows;
}
const out = {triangles: [], points: [], lines: []};
for (const t of cases.triangles) out.triangles.push({default: draw(null, gl.TRIANGLES, t, 1), fbo: draw(fbo, gl.TRIANGLES, t, 1)});
for (const p of cases.points) out.points.push({default: draw(null, gl.POINTS, [[p[0], p[1]]], p[2]), fbo: draw(fbo, gl.POINTS, [[p[0], p[1]]], p[2])});
for (const l of cases.lines) out.lines.push({default: draw(null, gl.LINES, l, 1), fbo: draw(fbo, gl.LINES, l, 1)});
out.point_size_range = Array.from(gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE));
out.line_width_range = Array.from(gl.getParameter(gl.ALIASED_LINE_WIDTH_RANGE));
out.renderer = gl.getParameter(gl.RENDERER);
result = out;
"""


def main():
    cases = {"triangles": triangle_cases(), "points": point_cases(), "lines": line_cases()}
    got = run_script(JS % {"size": SIZE, "cases": json.dumps(cases)})
    ref = {"chromium": chromium_version(), "renderer": got["renderer"], "size": SIZE,
           "point_size_range": got["point_size_range"], "line_width_range": got["line_width_range"],
           "triangles": [{"vertices": v, **c} for v, c in zip(cases["triangles"], got["triangles"])],
           "points": [{"point": v, **c} for v, c in zip(cases["points"], got["points"])],
           "lines": [{"vertices": v, **c} for v, c in zip(cases["lines"], got["lines"])]}
    OUT.write_text(json.dumps(ref, indent=0) + "\n")
    print("wrote", OUT)


if __name__ == "__main__":
    main()
