"""Memory that runs out: a job too large for the memory the server may use fails with a message
that says so and names the size (not "std::bad_alloc"), and the server goes on serving. The limit
is the process's address space (ulimit -v), set between what the server needs with the image
module loaded (about 1.3 GB here, most of it thread stacks and the module's libraries, reserved
rather than used) and what a 4096x4096 job adds (about 1.2 GB)."""
import os

import pytest

from support import TINY


@pytest.mark.skipif(bool(os.environ.get("PT_SANITIZED")),
                    reason="ulimit -v and AddressSanitizer's shadow memory do not mix")
def test_job_larger_than_memory_fails_saying_so(servers):
    srv = servers("memory", limit_memory_mib=1700, args=["--max-connections", "8"])
    api = srv.api
    first = api.submit(dict(TINY, width=16, height=12))  # loads the image module within the limit
    assert api.wait(first["id"], ("failed", "done"), timeout=30)["state"] == "done"
    big = api.submit({"scene": "cornell", "width": 4096, "height": 4096, "spp": 1, "max_depth": 1})
    failed = api.wait(big["id"], ("failed", "done"), timeout=60)
    assert failed["state"] == "failed", failed
    assert failed["message"] == "out of memory for a 4096x4096 image; a smaller size needs less", failed
    assert srv.alive()
    after = api.submit(dict(TINY, width=16, height=12))
    assert api.wait(after["id"], ("failed", "done"), timeout=30)["state"] == "done"
