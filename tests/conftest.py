import warnings

import pytest

import softgl

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
