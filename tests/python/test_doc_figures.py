"""Every figure the docs give for a shared model (../shared/data/qmvc, GPL, not
in this repository) is printed by a script, and the docs quote what it prints:
tests/python/doc_figures.py for docs/coordinates.md, tests/python/study.py
Beast for docs/python.md. Run whenever the shared data is there (CI has it),
so a change that moves a figure fails here until the docs follow."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import ROOT

SCRIPTS = ROOT / "tests" / "python"
SHARED = ROOT.parent / "shared" / "data" / "qmvc"


def run(*arguments: str) -> list[str]:
    result = subprocess.run([sys.executable, *arguments], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return [line for line in result.stdout.splitlines() if line]


def words(text: str) -> str:
    """Text with every run of white space one space: a sentence reads the same
    however the Markdown wraps it."""
    return " ".join(text.split())


@pytest.fixture(scope="module")
def shared():
    if not (SHARED / "Beast_Cage.obj").exists():
        pytest.skip(f"not run: {SHARED} (the shared models) is not there")
    return SHARED


def test_coordinates_md_quotes_the_shared_models_figures(shared):
    printed = run(str(SCRIPTS / "doc_figures.py"))
    assert len(printed) == 8 and not any("not run" in line for line in printed)
    doc = words((ROOT / "docs" / "coordinates.md").read_text())
    missing = [line for line in printed if words(line) not in doc]
    assert not missing, "docs/coordinates.md does not say:\n" + "\n".join(missing)


def test_python_md_quotes_the_beast_study(shared, tmp_path):
    printed = run(str(SCRIPTS / "study.py"), "Beast", "--figure", str(tmp_path / "beast.png"))
    lines = (ROOT / "docs" / "python.md").read_text().splitlines()
    # Every line but the bind times (which vary) and the figure's path is quoted verbatim.
    quoted = [line for line in printed if not line.startswith(("bind seconds:", "figure:"))]
    assert any(line.startswith("| QMVC |") for line in quoted), "Beast's quads make MVC QMVC"
    missing = [line for line in quoted if line not in lines]
    assert not missing, "docs/python.md does not quote these lines of the Beast study:\n" + "\n".join(missing)


def test_the_scripts_say_not_run_without_the_shared_data(tmp_path):
    """Where the data is missing the scripts say so and succeed, so that the
    docs' commands never fail for a reader without it."""
    for script in ("doc_figures.py", "study.py"):
        copy = tmp_path / "repo" / "tests" / "python" / script
        copy.parent.mkdir(parents=True, exist_ok=True)
        copy.write_text((SCRIPTS / script).read_text())
        arguments = [str(copy)] + (["Beast"] if script == "study.py" else [])
        printed = run(*arguments)
        assert len(printed) == 1 and "not run" in printed[0], printed
