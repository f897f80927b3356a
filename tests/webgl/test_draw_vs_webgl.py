"""softgl's pixels against real WebGL: every scene of scenes_draw.py, for each version, replayed
on softgl and compared call by call with the trace Chromium produced (reference/scenes_draw.json,
regenerate with `python tools/regen_webgl_references.py --scenes scenes_draw`).

Errors must match exactly (except the documented Chromium deviations below), getter results
exactly, readPixels images within 1/255 per byte. `python tests/webgl/test_draw_vs_webgl.py`
prints the agreement per scene and in total (share of pixels equal, within 1/255, max difference).
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import recorder  # noqa: E402
import scenes_draw  # noqa: E402
from webgl_rules import RULES  # noqa: E402

REFERENCE = recorder.load_traces(recorder.REFERENCE / "scenes_draw.json")

# Scenes where softgl is known to disagree with WebGL and softgl is wrong: strict xfails, so a
# fix turns them red and the entry must go. Each reason names the minimal repro.
KNOWN_SOFTGL_BUGS: dict[str, str] = {}

# Calls where Chromium departs from the WebGL/ES spec and softgl follows the spec:
# (scene id, call index) -> (Chromium's error, the spec's error, why).
CHROMIUM_DEVIATIONS: dict[tuple[str, int], tuple[int, int, str]] = {}


def cases(mark_known_bugs=True):
    out = []
    for case_id, fn, setup in scenes_draw.scene_cases():
        marks = ()
        if mark_known_bugs and case_id in KNOWN_SOFTGL_BUGS:
            marks = pytest.mark.xfail(strict=True, reason=KNOWN_SOFTGL_BUGS[case_id])
        out.append(pytest.param(case_id, fn, setup, id=case_id, marks=marks))
    return out


def run(case_id, fn, setup):
    """softgl's trace of one scene and the Chromium reference trace (checked to be of the same
    calls: a scene edited since the reference was made must be regenerated)."""
    reference = REFERENCE.get(case_id)
    assert reference is not None, f"no reference for {case_id}: regenerate the references"
    calls = recorder.record(fn, setup.version)
    assert reference["setup"] == setup.to_json(), f"{case_id}: setup changed: regenerate"
    assert [{k: e[k] for k in ("call", "args", "target") if k in e} for e in reference["trace"]] \
        == recorder.unpack(calls), f"{case_id}: the scene changed since the reference: regenerate"
    return recorder.run_softgl(setup, calls), reference["trace"]


def judged(case_id, trace, webgl):
    """Mismatches after applying the documented Chromium deviations (which must still hold)."""
    out = []
    for m in recorder.compare(trace, webgl, None, RULES):
        known = CHROMIUM_DEVIATIONS.get((case_id, m.index))
        if known and m.what == "error" and webgl[m.index]["error"] == known[0] \
                and trace[m.index]["error"] == known[1]:
            continue
        out.append(m)
    return out


@pytest.mark.parametrize("case_id, fn, setup", cases())
def test_scene_matches_webgl(case_id, fn, setup):
    trace, webgl = run(case_id, fn, setup)
    found = judged(case_id, trace, webgl)
    stats = recorder.pixel_stats(trace, webgl)
    assert not found, (f"{case_id}: {len({m.index for m in found})} of {len(trace)} calls differ "
                       f"from WebGL ({stats.share('equal'):.2%} of {stats.pixels} pixels equal, "
                       f"max diff {stats.max_diff}):\n" + "\n".join(map(str, found)))


@pytest.mark.parametrize("case_id, fn, setup", cases(mark_known_bugs=False))
def test_errors_come_with_a_warning(case_id, fn, setup):
    # softgl's own contract: a call that records an error emits one GLWarning; others none.
    trace = recorder.run_softgl(setup, recorder.record(fn, setup.version))
    bad = [f"#{i} {e['call']}: error {e['error']:#x}, warnings {e['warnings']}"
           for i, e in enumerate(trace)
           if e["thrown"] is None and (e["error"] != 0) != (len(e["warnings"]) == 1)]
    assert not bad, "\n".join(bad)


def test_corpus_covers_the_issue():
    ids = [c for c, _, _ in scenes_draw.scene_cases()]
    assert len(scenes_draw.SCENES) >= 40 and len(ids) == len(set(ids))
    assert set(ids) == {k for k in REFERENCE if not k.startswith("_")}, "regenerate the references"
    # every mode, factor, equation, depth function, stencil op and cull setting is drawn
    used = {}
    for case_id, fn, setup in scenes_draw.scene_cases():
        for e in recorder.record(fn, setup.version):
            used.setdefault(e["call"], set()).update(
                a for a in e["args"] if isinstance(a, int) and not isinstance(a, bool))
    names = recorder.ENUMS["webgl2"]
    modes = {names[m] for m in ("POINTS", "LINES", "LINE_STRIP", "LINE_LOOP", "TRIANGLES",
                                "TRIANGLE_STRIP", "TRIANGLE_FAN")}
    assert modes <= used["drawArrays"] and {names["TRIANGLES"]} <= used["drawElements"]
    assert {names[f] for f in scenes_draw.BLEND_FACTORS} <= used["blendFunc"]
    assert {names[e] for e in ("FUNC_ADD", "FUNC_SUBTRACT", "FUNC_REVERSE_SUBTRACT")} | \
        {scenes_draw.MIN_EXT, scenes_draw.MAX_EXT} <= used["blendEquation"]
    assert {names[f] for f in scenes_draw.DEPTH_FUNCS} <= used["depthFunc"] & used["stencilFunc"]
    assert {names[o] for o in scenes_draw.STENCIL_OPS} <= used["stencilOp"]
    assert {names["FRONT"], names["BACK"], names["FRONT_AND_BACK"]} <= used["cullFace"]
    assert {names["CW"], names["CCW"]} <= used["frontFace"]


def test_reference_size_is_reasonable():
    assert (recorder.REFERENCE / "scenes_draw.json").stat().st_size < 5_000_000


def summary():
    """Per-scene agreement and totals, for the report."""
    total = recorder.PixelStats()
    worst = None
    lines = []
    for case_id, fn, setup in scenes_draw.scene_cases():
        trace, webgl = run(case_id, fn, setup)
        found = judged(case_id, trace, webgl)
        stats = recorder.pixel_stats(trace, webgl)
        total += stats
        if stats.pixels and (worst is None or stats.share() < worst[1].share()):
            worst = (case_id, stats)
        errors = sum(m.what != "result" for m in found)
        flag = " XFAIL" if case_id in KNOWN_SOFTGL_BUGS else ""
        lines.append(f"{case_id:48s} {stats.pixels:7d} px  equal {stats.share('equal'):8.4%}  "
                     f"within 1/255 {stats.share():8.4%}  max {stats.max_diff:3d}  "
                     f"other mismatches {errors}{flag}")
    print("\n".join(lines))
    print(f"\n{len(scenes_draw.SCENES)} scenes, {len(lines)} scene x version runs, "
          f"{total.pixels} pixels compared")
    print(f"equal {total.share('equal'):.4%}, within 1/255 {total.share():.4%}, "
          f"max diff {total.max_diff}")
    if worst:
        print(f"worst scene {worst[0]}: within 1/255 {worst[1].share():.4%}, "
              f"max diff {worst[1].max_diff}")


if __name__ == "__main__":
    summary()
