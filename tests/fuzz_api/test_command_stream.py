"""API command-stream fuzzing in CI (bounded): hypothesis drives sequences of fuzzer steps on two
contexts (strict and not, WebGL 1 or 2); every call must either succeed or report its WebGL error
and change nothing, and the process must survive. See command_stream.py and docs/reliability.md;
tools/fuzz_api.py runs the same fuzzer for hours."""
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, settings, strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule

import softgl
from command_stream import CommandFuzzer, Violation


class CommandStream(RuleBasedStateMachine):
    @initialize(seed=st.integers(0, 2**32 - 1), version=st.sampled_from([1, 2]))
    def start(self, seed, version):
        self.fuzzer = CommandFuzzer(seed, version)

    @rule(steps=st.integers(1, 8))
    def calls(self, steps):
        # Each hypothesis step runs a few fuzzer steps; their randomness comes from the seed,
        # so a failure shrinks to the shortest sequence of seeds and step counts.
        with np.errstate(over="ignore", invalid="ignore"):
            for _ in range(steps):
                self.fuzzer.step()

    @rule(seed=st.integers(0, 2**32 - 1))
    def reseed(self, seed):
        self.fuzzer.rng = np.random.default_rng(seed)

    @invariant()
    def contexts_still_answer(self):
        if hasattr(self, "fuzzer"):
            for side in self.fuzzer.sides:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", softgl.GLWarning)
                    assert side.gl.isContextLost() is False
                    assert side.gl.drawingBufferWidth == 4


CommandStream.TestCase.settings = settings(
    max_examples=100, stateful_step_count=40, deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
test_command_stream = CommandStream.TestCase


@pytest.mark.parametrize("seed", range(6))
def test_fixed_seeds(seed):
    """Deterministic runs that always execute (hypothesis may vary between runs)."""
    f = CommandFuzzer(seed * 7919 + 1)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(250):
            f.step()
    assert f.calls > 150 and f.errors > 20


def test_violation_is_detected():
    """The contract check can fail: a call that changes state and also reports an error."""
    f = CommandFuzzer(1, version=2)
    side = f.sides[0]
    side.strict = False
    real = side.gl.__class__.clearColor

    class Lying(type(side.gl)):
        pass

    def bad_clear_color(gl, *args):
        real(gl, 0.25, 0.5, 0.75, 1.0)
        gl.enable(0xDEAD)          # reports INVALID_ENUM after changing the clear color
    side.gl.__class__ = Lying
    Lying.clearColor = bad_clear_color
    with pytest.raises(Violation, match="changed the state"):
        f._call(side, "clearColor", (0.0, 0.0, 0.0, 0.0))
