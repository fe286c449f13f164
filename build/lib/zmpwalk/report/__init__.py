"""Reports: paper-style plots, the interactive replay of a simulated walk (three.js), the optional offscreen GIF, and a
self-contained HTML page."""

from zmpwalk.report.page import Report, build_report

__all__ = ["Report", "build_report"]
