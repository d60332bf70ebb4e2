"""The worked study of docs/python.md runs, and the doc quotes what it prints."""

from __future__ import annotations

import subprocess
import sys

from conftest import ROOT


def test_the_study_runs_on_the_comb_and_docs_quote_its_table(tmp_path):
    figure = tmp_path / "study-comb.png"
    result = subprocess.run(
        [sys.executable, str(ROOT / "tests" / "python" / "study.py"), "comb", "--figure", str(figure)],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    assert figure.stat().st_size > 10_000 and figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    doc = (ROOT / "docs" / "python.md").read_text()
    # Every line but the bind times (which vary) is quoted verbatim.
    printed = [
        line
        for line in result.stdout.splitlines()
        if line and not line.startswith(("bind seconds:", "figure:"))
    ]
    missing = [line for line in printed if line not in doc.splitlines()]
    assert not missing, "docs/python.md does not quote these lines of the study:\n" + "\n".join(missing)
