"""Missions made of many paths: coverage (zigzag + DE + FM²), formations."""

from .coverage import Zigzag, plan_coverage, zigzag

__all__ = ["Zigzag", "zigzag", "plan_coverage"]
