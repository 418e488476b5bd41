"""The report as PDF, printed by headless Chromium (the Debian package ``chromium``)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import BackendUnavailableError, HiabSimError

BROWSERS = ("chromium", "chromium-browser", "google-chrome")


def browser() -> str:
    """Path of a headless-capable Chromium; BackendUnavailableError says how to install one."""
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    raise BackendUnavailableError("--pdf needs Chromium to print the page: apt-get install chromium")


def print_pdf(html_file: Path, pdf_file: Path, timeout_s: float = 120.0) -> Path:
    """Print ``html_file`` to ``pdf_file`` (atomically) with headless Chromium."""
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "report.pdf"
        command = [
            browser(),
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            f"--user-data-dir={folder}/profile",
            "--no-pdf-header-footer",
            f"--print-to-pdf={target}",
            html_file.resolve().as_uri(),
        ]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s, check=False)
        if done.returncode != 0 or not target.is_file():
            raise HiabSimError(f"chromium could not print {html_file}: {done.stderr.strip()[-300:]}")
        write_atomic(pdf_file, target.read_bytes())
    return pdf_file
