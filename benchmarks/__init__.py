"""Benchmarks of fm2uav: run with ``python -m benchmarks.run`` (``make bench``)."""
