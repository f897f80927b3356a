import pytest

import softgl


@pytest.fixture
def gl():
    return softgl.Context(32, 24, antialias=False)
