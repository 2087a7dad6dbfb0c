"""Fixtures: the OpenAPI contract, and render-server processes that are always killed at the end."""
import pytest

from support import Contract, Server


@pytest.fixture(scope="session")
def contract():
    return Contract.load()


@pytest.fixture
def servers(tmp_path, contract):
    """Starts servers: servers(name, threads=, args=). The same name reuses its data directory."""
    started = []

    def start(name="server", **kw):
        root = tmp_path / name
        root.mkdir(exist_ok=True)
        srv = Server(root, contract, **kw)
        started.append(srv)
        return srv.start()

    yield start
    for srv in started:
        srv.kill()
    for srv in started:  # shown by pytest when the test failed
        print(f"---- {srv.log_path} ----\n{srv.log_text()[-4000:]}")


@pytest.fixture
def server(servers):
    return servers()


def pytest_terminal_summary(terminalreporter):
    # The figures docs/reliability.md quotes: how many requests the tests sent, how many got a 5xx.
    from support import STATS
    terminalreporter.write_line(f"render-server requests sent: {STATS['requests']}, 5xx answers: {STATS['5xx']} "
                                f"(500 Internal Server Error: {STATS['500']})")
