"""Figures: matplotlib PNGs and interactive HTML reports (drawing only)."""

from .figures import plan_figure
from .report import plan_report, report_html, write_report

__all__ = ["plan_figure", "plan_report", "report_html", "write_report"]
