"""Settings every test shares: the in-process test client's `Host` is allowed.

Starlette's TestClient sends `Host: testserver`, which the server's DNS-rebinding guard refuses
(server/hosts.py). The tests' servers accept that one name through HORDE_ALLOWED_HOSTS, as a user
would allow a name of theirs; the built-in default stays empty (tests/server/test_hosts.py).
"""

from __future__ import annotations

import os

os.environ["HORDE_ALLOWED_HOSTS"] = '["testserver"]'
