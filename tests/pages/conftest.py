from pathlib import Path

import pytest

LESSONS = Path(__file__).parent / "lessons"

pytest.importorskip("STPyV8", reason="softgl.page needs the STPyV8 wheel (pip install 'softgl[pages]')")


@pytest.fixture
def lessons() -> Path:
    return LESSONS
