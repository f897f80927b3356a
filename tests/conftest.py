import warnings

import pytest
from hypothesis import settings

import softgl

# Property tests draw the same examples on every run (CI must not pass or fail by chance); the
# long randomized runs are the fuzzers' job (tools/run_fuzzers.sh, tools/fuzz_api.py).
settings.register_profile("softgl", derandomize=True, database=None)
settings.load_profile("softgl")

pytest_plugins = ["softgl.pytest_plugin"]


@pytest.fixture(params=[1, 2], ids=["webgl1", "webgl2"])
def version(request):
    return request.param


@pytest.fixture
def quiet():
    """Silence GLWarnings inside a test that provokes errors on purpose."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", softgl.GLWarning)
        yield
