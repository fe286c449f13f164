"""Reports: paper-style plots, the offscreen animation of a simulated walk, and a self-contained HTML page."""

from zmpwalk.report.page import Report, build_report

__all__ = ["Report", "build_report"]
