"""The design report: one self-contained HTML file of a result folder, to hand on (``hiab-sim report``)."""

from hiab_sim.design_report.build import report_html, write_report

__all__ = ["report_html", "write_report"]
