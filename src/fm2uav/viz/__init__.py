"""Figures: matplotlib PNGs (and interactive HTML reports)."""

from .figures import plan_figure

__all__ = ["plan_figure"]
