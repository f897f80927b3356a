"""The judge itself: recording, encoding and comparison must notice every kind of difference."""
from __future__ import annotations

import copy
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import recorder  # noqa: E402
from recorder import Setup, compare, decode_arg, encode, record, run_softgl  # noqa: E402
from webgl_rules import RULES  # noqa: E402


def sample_scene(gl):
    gl.clearColor(0.25, float("nan"), float("inf"), 1)
    gl.getParameter(gl.COLOR_CLEAR_VALUE)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(0x0B60)
    gl.readPixels(0, 0, 2, 1, gl.RGBA, gl.UNSIGNED_BYTE)
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, np.full((1, 1, 4), 3, np.uint8))


def test_recording_gives_constants_and_calls():
    calls = record(sample_scene, 1)
    assert [c["call"] for c in calls] == ["clearColor", "getParameter", "clear", "enable",
                                          "readPixels", "readPixels"]
    assert calls[0]["args"] == [0.25, {"num": "NaN"}, {"num": "Infinity"}, 1]
    assert calls[1]["args"] == [0x0C22]
    assert calls[5]["args"][6] == {"type": "Uint8Array", "values": [3] * 4, "shape": [1, 1, 4]}


def test_version_1_proxy_has_no_webgl2_constants():
    def scene(gl):
        gl.enable(gl.RASTERIZER_DISCARD)
    record(scene, 2)
    try:
        record(scene, 1)
    except AttributeError:
        return
    raise AssertionError("WebGL 1 has no RASTERIZER_DISCARD")


def test_encoding_round_trip():
    arr = np.array([1.5, -np.inf, np.nan], np.float32)
    enc = encode(arr)
    assert enc == {"type": "Float32Array", "values": [1.5, {"num": "-Infinity"}, {"num": "NaN"}]}
    back = decode_arg(enc)
    assert back.dtype == np.float32 and back[0] == 1.5 and math.isinf(back[1]) and np.isnan(back[2])
    assert encode({"b": [True, None], "a": 2}) == {"a": 2, "b": [True, None]}


def test_softgl_trace_has_errors_results_and_arrays():
    trace = run_softgl(Setup(version=2, width=4, height=4), record(sample_scene, 2))
    assert [e["error"] for e in trace] == [0, 0, 0, 0x500, 0, 0]
    assert trace[1]["result"]["type"] == "Float32Array"
    assert trace[4]["result"]["type"] == "Uint8Array" and len(trace[4]["result"]["values"]) == 8
    assert trace[3]["warnings"] and not trace[2]["warnings"]


def _trace():
    return run_softgl(Setup(version=2, width=4, height=4), record(sample_scene, 2))


def test_compare_agrees_with_itself():
    assert compare(_trace(), _trace()) == []


def test_compare_reports_each_kind_of_difference():
    a = _trace()
    b = copy.deepcopy(a)
    b[3]["error"] = 0                                    # error sequence
    b[1]["result"]["values"][0] = 0.25 + 1e-3            # beyond float32 tolerance
    b[4]["result"]["values"][0] += 2                     # beyond 1/255
    b[2]["thrown"] = "TypeError"
    found = {(m.index, m.what) for m in compare(a, b)}
    assert found == {(3, "error"), (1, "result"), (4, "result"), (2, "thrown")}


def test_compare_tolerances():
    a = _trace()
    b = copy.deepcopy(a)
    b[1]["result"]["values"][0] = float(np.nextafter(np.float32(0.25), np.float32(1)))
    b[4]["result"]["values"][0] += 1                     # one step of 1/255 is allowed
    assert compare(a, b) == []
    b[1]["result"]["values"][1] = 0.0                    # NaN only matches NaN
    assert [m.index for m in compare(a, b)] == [1]


def test_pixel_mismatch_message_has_share_and_max():
    why = recorder.pixels_match({"type": "Uint8Array", "values": [0, 0, 0, 10] + [5] * 12},
                                {"type": "Uint8Array", "values": [0, 0, 0, 0] + [5] * 12})
    assert "75.0% of pixels equal" in why and "max diff 10" in why


def test_rules_accept_limits_but_not_below_minimum():
    setup = Setup(version=2, width=16, height=16)
    entry = {"call": "getParameter", "args": [0x0D33], "error": 0}      # MAX_TEXTURE_SIZE
    assert RULES[1](setup, entry, 16384, 8192) is None
    assert "2048" in RULES[1](setup, entry, 1024, 8192)
    draw_buffer1 = {"call": "getParameter", "args": [0x8826], "error": 0}
    assert RULES[0](setup, draw_buffer1, 0, 0x0405) is None             # spec NONE, Chromium BACK
    assert RULES[0](setup, draw_buffer1, 0x0405, 0x0405)                # copying Chromium is wrong


def handle_scene(gl):
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.getParameter(gl.ARRAY_BUFFER_BINDING)
    ext = gl.getExtension("OES_vertex_array_object")
    gl.expect("note").bindVertexArrayOES(None)
    ext.createVertexArrayOES()


def test_results_become_handles_for_later_calls():
    calls = record(handle_scene, 1)
    assert calls[1]["args"][1] == {"ref": 0}              # the buffer createBuffer returned
    assert calls[5] == {"call": "createVertexArrayOES", "args": [], "target": 3}
    assert calls[4]["expect"] == "note"
    trace = run_softgl(Setup(version=1, width=4, height=4), calls)
    assert trace[0]["result"] == {"object": "WebGLBuffer"}
    assert trace[2]["result"] == {"object": "WebGLBuffer"}   # the same buffer was bound
    assert trace[5]["result"] == {"object": "WebGLVertexArrayObject"} and not trace[5]["thrown"]


def test_packed_arrays_round_trip():
    value = {"trace": [{"result": {"type": "Uint8Array", "values": list(range(200))}},
                       {"result": {"type": "Float32Array", "values": [0.5] * 100, "shape": [100]}},
                       {"result": {"type": "Uint8Array", "values": [1, 2]}}]}
    packed = recorder.pack(value)
    assert "zlib" in packed["trace"][0]["result"] and "values" in packed["trace"][2]["result"]
    assert recorder.unpack(packed) == value


def test_pixel_stats_count_pixels_not_bytes():
    a = [{"call": "readPixels", "result": {"type": "Uint8Array", "values": [0] * 16}}]
    b = [{"call": "readPixels", "result": {"type": "Uint8Array", "values": [0, 1, 0, 0] + [0] * 8 + [9, 0, 0, 9]}}]
    st = recorder.pixel_stats(a, b)
    assert (st.pixels, st.equal, st.within, st.max_diff) == (4, 2, 3, 9)
