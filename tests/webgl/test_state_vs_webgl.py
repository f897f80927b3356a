"""softgl against real WebGL: every scene of scenes_state.py, for each version, replayed on softgl
and compared call by call with the trace Chromium produced (reference/scenes_state.json).

Errors must match exactly, values within float32 tolerance, pixels within 1/255; implementation
limits, strings and extensions are judged by webgl_rules.py. Regenerate the reference with
`python tools/regen_webgl_references.py --scenes` after editing a scene.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import recorder  # noqa: E402
import scenes_state  # noqa: E402
from webgl_rules import RULES  # noqa: E402

REFERENCE = json.loads((recorder.REFERENCE / "scenes_state.json").read_text())

# Scenes where softgl is known to be wrong (the report lists each one precisely). strict=True:
# the test turns red when the C++ is fixed, so this list only ever shrinks.
# Scenes where softgl is known to disagree with WebGL: strict xfails, so a fix flips them.
KNOWN_SOFTGL_BUGS: dict[str, str] = {}


def cases(mark_known_bugs=True):
    out = []
    for case_id, fn, setup in scenes_state.scene_cases():
        marks = ()
        if mark_known_bugs and case_id in KNOWN_SOFTGL_BUGS:
            marks = pytest.mark.xfail(strict=True, reason=KNOWN_SOFTGL_BUGS[case_id])
        out.append(pytest.param(case_id, fn, setup, id=case_id, marks=marks))
    return out


def mismatches(case_id, fn, setup):
    """Run one scene on softgl; the list of disagreements with the Chromium reference."""
    reference = REFERENCE.get(case_id)
    assert reference is not None, f"no reference for {case_id}: regenerate the references"
    calls = recorder.record(fn, setup.version)
    assert reference["setup"] == setup.to_json(), f"{case_id}: setup changed: regenerate"
    assert [{"call": e["call"], "args": e["args"]} for e in reference["trace"]] == \
        json.loads(json.dumps(calls)), f"{case_id}: the scene changed since the reference: regenerate"
    trace = recorder.run_softgl(setup, calls)
    return trace, recorder.compare(trace, reference["trace"], setup, RULES)


@pytest.mark.parametrize("case_id, fn, setup", cases())
def test_scene_matches_webgl(case_id, fn, setup):
    trace, found = mismatches(case_id, fn, setup)
    calls = len({m.index for m in found})
    assert not found, f"{case_id}: {calls} of {len(trace)} calls differ from WebGL:\n" + \
        "\n".join(map(str, found))


@pytest.mark.parametrize("case_id, fn, setup", cases(mark_known_bugs=False))
def test_errors_come_with_a_warning(case_id, fn, setup):
    # softgl's own contract: a call that records an error emits one GLWarning; others none.
    trace = recorder.run_softgl(setup, recorder.record(fn, setup.version))
    bad = [f"#{i} {e['call']}{tuple(e['args'])}: error {e['error']:#x}, warnings {e['warnings']}"
           for i, e in enumerate(trace)
           if e["thrown"] is None and (e["error"] != 0) != (len(e["warnings"]) == 1)]
    assert not bad, "\n".join(bad)


def test_corpus_size():
    ids = [c for c, _, _ in scenes_state.scene_cases()]
    assert len(scenes_state.SCENES) >= 40 and len(ids) == len(set(ids))
    assert set(ids) == {k for k in REFERENCE if not k.startswith("_")}, "regenerate the references"


def summary():
    """Numbers for a report: scenes, calls compared, how many match (and how many by a rule)."""
    runs = calls = equal = by_rule = 0
    lines = []
    for case_id, fn, setup in scenes_state.scene_cases():
        trace, found = mismatches(case_id, fn, setup)
        plain = recorder.compare(trace, REFERENCE[case_id]["trace"], setup)
        bad = {m.index for m in found}
        runs += 1
        calls += len(trace)
        equal += len(trace) - len({m.index for m in plain})
        by_rule += len({m.index for m in plain} - bad)
        lines += [f"{case_id}: {m}" for m in found]
    print(f"{len(scenes_state.SCENES)} scenes, {runs} scene x version runs, {calls} calls compared")
    print(f"identical {equal}, accepted by a rule {by_rule}, mismatching {calls - equal - by_rule}")
    print("\n".join(lines))


if __name__ == "__main__":
    summary()
