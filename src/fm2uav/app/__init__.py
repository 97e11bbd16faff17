"""The local web app of ``fm2uav app``: plan missions on a map in the browser.

A FastAPI server on 127.0.0.1 (:mod:`.server`) serves a Leaflet map page
(``static/``, the shared map script in ``fm2uav/viz/web``), the user's DEM as
shaded relief tiles and contours (:mod:`.terrain`, rio-tiler), and runs the
library's own functions in a worker process (:mod:`.jobs`, :mod:`.worker`):
a planning job is ``fm2uav run`` on the mission file the page describes, so the
files it offers for download are those ``fm2uav run`` writes from the saved
mission file. The app holds no planning logic.
"""

from __future__ import annotations

import socket
import threading
import webbrowser
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["serve", "bind"]


def bind(port: int) -> socket.socket:
    """A listening TCP socket on 127.0.0.1:``port`` (0: a free port).

    Raises
    ------
    InputError
        The port is in use or not allowed (names ``--port``).
    """
    from ..errors import InputError

    if not 0 <= port <= 65535:
        raise InputError(f"--port {port} is not a TCP port; allowed: 0 (a free one) to 65535")
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(("127.0.0.1", port))
    except OSError as exc:
        sock.close()
        raise InputError(f"--port {port}: cannot listen on 127.0.0.1:{port} ({exc.strerror}); "
                         "give another port, or --port 0 for a free one") from None
    sock.listen(64)
    return sock


def serve(mission: dict[str, Any], *, folder: str | Path, mission_path: str | Path,
          port: int = 8765, open_browser: bool = True,
          announce: Callable[[str], None] = print) -> None:
    """Run the app until interrupted (Ctrl-C).

    Parameters
    ----------
    mission : dict
        The mission document the page starts with (mission-file schema).
    folder : path
        The session folder (uploads, jobs' files).
    mission_path : path
        Where "Save" writes by default.
    port : int
        TCP port on 127.0.0.1 (0: a free one).
    open_browser : bool
        Open the page in the default browser once the server listens.
    announce : callable
        Receives the line with the URL.
    """
    import uvicorn

    from .jobs import JobManager
    from .server import create_app
    from .session import Session

    sock = bind(port)
    url = f"http://127.0.0.1:{sock.getsockname()[1]}/"
    jobs = JobManager()
    app = create_app(Session(folder, mission, mission_path), jobs)
    config = uvicorn.Config(app, log_level="warning", lifespan="off", access_log=False)
    server = uvicorn.Server(config)
    announce(url)
    if open_browser:
        threading.Timer(0.5, webbrowser.open, args=(url,)).start()
    try:
        server.run(sockets=[sock])
    finally:
        jobs.close()
        sock.close()
