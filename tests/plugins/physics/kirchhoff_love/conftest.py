"""The small clamped quarter plate of test_analysis as a fixture (patches: ../../conftest.py)."""
import pytest


@pytest.fixture(scope="module")
def quarter_plate():
    """(settings, model) of the small clamped quarter plate of test_analysis (central load)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "shell_plate_case", Path(__file__).with_name("test_analysis.py"))
    case = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(case)
    s = case._settings()
    return s, case._model(s)
