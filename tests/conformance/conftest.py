"""Conformance port: our own pytest re-expression of what the WebGL conformance suite
(KhronosGroup/WebGL sdk/tests/conformance, conformance2) and dEQP (VK-GL-CTS
modules/gles2/functional, gles3/functional) check. Folders follow theirs; docs/conformance.md
maps each of their tests to ours (or says why it is not covered)."""
import warnings

import pytest

import softgl


@pytest.fixture(autouse=True)
def _no_console_noise():
    # These tests provoke GL errors on purpose and check getError(); the GLWarnings that come
    # with them (softgl's "browser console") are tested in tests/api/test_errors.py.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", softgl.GLWarning)
        yield
