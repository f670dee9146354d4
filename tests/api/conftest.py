import pytest


@pytest.fixture(scope="session")
def default_result():
    """The embedded default scene, designed once for the API and result tests."""
    import chargedesign as cd

    return cd.design()
