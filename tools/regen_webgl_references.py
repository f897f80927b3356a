"""Regenerate tests/webgl/reference/{enums,initial_parameters}.json from real WebGL in Chromium.

    python tools/regen_webgl_references.py      (needs `apt-get install chromium`)

enums.json: every numeric constant of WebGLRenderingContext and WebGL2RenderingContext.
initial_parameters.json: for each context version, every constant that getParameter accepts
(no error), with the type and value it returns on a fresh 300x150 context.
"""
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "webgl"))
from chromium import chromium_version, run_script  # noqa: E402

REF = ROOT / "tests" / "webgl" / "reference"

ENUMS_JS = r"""
function consts(proto) {
  const r = {};
  for (const k of Object.getOwnPropertyNames(proto)) {
    const d = Object.getOwnPropertyDescriptor(proto, k);
    if (d && typeof d.value === 'number' && /^[A-Z0-9_]+$/.test(k)) r[k] = d.value;
  }
  return r;
}
result = {webgl1: consts(WebGLRenderingContext.prototype),
          webgl2: consts(WebGL2RenderingContext.prototype)};
"""

PARAMS_JS = r"""
function enc(v) {
  if (v === null) return {t: 'null'};
  if (typeof v === 'boolean') return {t: 'bool', v};
  if (typeof v === 'number') return {t: 'number', v};
  if (typeof v === 'string') return {t: 'string', v};
  if (Array.isArray(v)) return {t: 'array', v};
  for (const T of [Float32Array, Int32Array, Uint32Array])
    if (v instanceof T) return {t: T.name, v: Array.from(v)};
  return {t: Object.prototype.toString.call(v)};
}
function dump(version) {
  const canvas = document.createElement('canvas');
  canvas.width = 300; canvas.height = 150;
  const gl = canvas.getContext(version == 1 ? 'webgl' : 'webgl2',
                               {antialias: false, preserveDrawingBuffer: true});
  const proto = version == 1 ? WebGLRenderingContext.prototype : WebGL2RenderingContext.prototype;
  const params = {};
  for (const k of Object.getOwnPropertyNames(proto).filter(k => /^[A-Z0-9_]+$/.test(k))) {
    gl.getError();
    let v;
    try { v = gl.getParameter(gl[k]); } catch (e) { params[k] = {t: 'throw'}; continue; }
    if (gl.getError() === 0) params[k] = enc(v);
  }
  return {params, attrs: gl.getContextAttributes(),
          extensions: gl.getSupportedExtensions()};
}
result = {v1: dump(1), v2: dump(2)};
"""


def main():
    version = chromium_version()
    enums = run_script(ENUMS_JS)
    (REF / "enums.json").write_text(json.dumps(enums, indent=1, sort_keys=True))
    params = run_script(PARAMS_JS)
    params.update(chromium=version, canvas=[300, 150])
    (REF / "initial_parameters.json").write_text(json.dumps(params, indent=1, sort_keys=True))
    print(f"wrote {REF} from {version}")


if __name__ == "__main__":
    main()
