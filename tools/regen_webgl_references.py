"""Regenerate tests/webgl/reference/*.json from real WebGL in Chromium.

    python tools/regen_webgl_references.py            (needs `apt-get install chromium`)
    python tools/regen_webgl_references.py --scenes   (only the scene traces, enums kept)
    python tools/regen_webgl_references.py --scenes scenes_draw   (only the named corpora)

enums.json: every numeric constant of WebGLRenderingContext and WebGL2RenderingContext.
initial_parameters.json: for each context version, every constant that getParameter accepts
(no error), with the type and value it returns on a fresh 300x150 context.
<corpus>.json (e.g. scenes_state.json): for each scene corpus in tests/webgl/ (SCENE_CORPORA), the
trace of every scene x version replayed in Chromium (tests/webgl/recorder.py); the tests compare
softgl against these files and never need Chromium. Regenerate after editing a corpus. Corpora
with images (PACKED = True in the module) store readPixels results zlib-compressed.
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
    if (d && typeof d.value === 'number' && /^[A-Z][A-Z0-9_x]*$/.test(k)) r[k] = d.value;
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
  for (const k of Object.getOwnPropertyNames(proto).filter(k => /^[A-Z][A-Z0-9_x]*$/.test(k))) {
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


SCENE_CORPORA = ["scenes_state", "scenes_draw"]


def regen_scenes(version, corpora=SCENE_CORPORA):
    """Replay every scene of every corpus in Chromium and store the traces."""
    import importlib
    import recorder
    for corpus in corpora:
        module = importlib.import_module(corpus)
        cases = {case_id: (setup, recorder.record(fn, setup.version))
                 for case_id, fn, setup in module.scene_cases()}
        traces = recorder.run_webgl(cases)
        out = {"_about": {"chromium": version,
                          "command": f"python tools/regen_webgl_references.py --scenes {corpus}",
                          "trace": []}}
        for case_id, (setup, _) in cases.items():
            out[case_id] = {"setup": setup.to_json(), "trace": traces[case_id]}
        (REF / f"{corpus}.json").write_text(
            recorder.dump_traces(out, packed=getattr(module, "PACKED", False)))
        calls = sum(len(t) for t in traces.values())
        print(f"wrote {REF / corpus}.json: {len(cases)} scene runs, {calls} calls")


def main():
    version = chromium_version()
    args = sys.argv[1:]
    if "--scenes" not in args:
        enums = run_script(ENUMS_JS)
        (REF / "enums.json").write_text(json.dumps(enums, indent=1, sort_keys=True))
        params = run_script(PARAMS_JS)
        params.update(chromium=version, canvas=[300, 150])
        (REF / "initial_parameters.json").write_text(json.dumps(params, indent=1, sort_keys=True))
        print(f"wrote {REF} from {version}")
    named = [a for a in args if not a.startswith("--")]
    unknown = set(named) - set(SCENE_CORPORA)
    if unknown:
        sys.exit(f"unknown corpora {sorted(unknown)}; known: {SCENE_CORPORA}")
    regen_scenes(version, named or SCENE_CORPORA)


if __name__ == "__main__":
    main()
