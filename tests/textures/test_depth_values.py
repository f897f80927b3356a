"""The depth texels' values (sampler.cpp depth_values8): a fixed-point depth word w of n bits
becomes the float nearest to w / (2^n - 1) (ES 3.0 §2.1.6; texture.cpp depth_value divides in
double). The SIMD blocks multiply by the double reciprocal of 2^n - 1 instead; the claim that
this rounds to the same float for every word is checked here exhaustively in float64 (the exact
quotient's float from numpy's correctly rounded division), and the blocks are checked against
the per-lane general path on random words by the shadow-sampler A/B tests
(test_sampling_shadow_cube.py)."""
import numpy as np
import pytest


@pytest.mark.parametrize("bits", [16, 24])
def test_reciprocal_product_rounds_to_the_quotient_float_for_every_word(bits):
    divisor = float(2 ** bits - 1)
    for start in range(0, 2 ** bits, 1 << 22):
        w = np.arange(start, min(start + (1 << 22), 2 ** bits), dtype=np.float64)
        quotient = (w / divisor).astype(np.float32)
        product = (w * (1.0 / divisor)).astype(np.float32)
        assert np.array_equal(quotient.view(np.uint32), product.view(np.uint32))
    # ... which is not true of a float32 reciprocal: the rule needs the double product.
    w = np.arange(2 ** bits, dtype=np.float64)
    single = (w.astype(np.float32) * np.float32(1.0 / divisor)).astype(np.float32)
    assert (single != (w / divisor).astype(np.float32)).any()
