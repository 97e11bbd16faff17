"""Reproductions of the source papers' experiments, and parameter sweeps.

One module per experiment (``tff``, ``urban``, ``city``, ``coverage``, ``formation``,
``curvature``) holding its seed tables and returning results; nothing here prints,
parses options or draws. ``sweep`` / ``runner`` run the α–β sweeps.
"""
