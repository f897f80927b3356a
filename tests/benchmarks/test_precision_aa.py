"""Smoke test of benchmarks/precision_aa.py on tiny scenes: the orderings the table shows."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import precision_aa  # noqa: E402


def test_antialiasing_errors_order():
    rows, check = precision_aa.aa_rows("rotated square", 24, 1)
    err = {name: rmse for name, _, rmse, _, _ in rows}
    assert check < 2e-3                                   # the analytic reference agrees with 32x32 SSAA
    assert err["analytic NICEST (exact)"] < 2e-3          # only 8-bit rounding left
    assert err["analytic NICEST (exact)"] < err["SSAA 8x8"] < err["SSAA 2x2"] < err["none"]
    assert err["MSAA 16x"] < err["none"]


def test_precision_errors_order():
    rows = precision_aa.precision_rows(4, 1, (10,))
    err = {name: rmse for name, _, rmse, _, _ in rows}
    for kind in precision_aa.BLENDS:
        assert err[f"{kind} 10 float64"] == 0
        assert err[f"{kind} 10 rgba32f"] < 1e-6 < err[f"{kind} 10 rgba16f"] < err[f"{kind} 10 rgba8"]
