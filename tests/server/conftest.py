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
