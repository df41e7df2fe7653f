"""Suite-wide pytest settings: markers only (fixtures live next to their tests)."""


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "slow: takes minutes (e.g. builds and installs the Blender extension); left out of "
        "tasks.py test's default run (CI's), run with -m slow or -m ''")
