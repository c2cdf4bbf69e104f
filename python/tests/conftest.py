"""The tests' markers."""


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "verilated: runs a Verilated board (its library is built for this machine; "
        "scripts/python.sh --aarch64-run leaves these out)",
    )
