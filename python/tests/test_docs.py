"""Every Python block of README.md and docs/*.md runs as written (from the repository root).

A block runs here unless the line just above its fence says otherwise:
- `<!-- run by python/tests/NAME.py -->`: another test runs it (that file must name the page);
- `<!-- not run: REASON -->`: it needs what no test machine has (a batch scheduler, say); it
  is still compiled here, so a syntax error or a renamed keyword of Python fails.
"""

import os
import re
import textwrap

import pytest

from conftest import ROOT

FENCE = re.compile(r"^([ \t]*)```python\n(.*?)^\1```", flags=re.S | re.M)
MARK = re.compile(r"<!-- (run by (python/tests/\S+\.py)|not run: [^>]+) -->\s*$")


def blocks():
    """(page, index, code, marker match or None) for every Python block."""
    pages = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    found = []
    for page in pages:
        text = page.read_text()
        for i, m in enumerate(FENCE.finditer(text)):
            before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1]
            code = textwrap.dedent(m.group(2))
            found.append((page.relative_to(ROOT).as_posix(), i, code, MARK.search(before)))
    return found


BLOCKS = blocks()
RUN_HERE = [(p, i, c) for p, i, c, mark in BLOCKS if mark is None]


def test_the_pages_have_python_blocks():
    assert len([b for b in RUN_HERE if b[0] == "docs/python.md"]) >= 3


def test_every_block_is_run_or_says_why_not():
    for page, i, code, mark in BLOCKS:
        compile(code, f"{page} block {i}", "exec")  # at least it parses
        if mark is not None and mark.group(2):
            runner = ROOT / mark.group(2)
            assert runner.is_file(), f"{page} block {i}: {mark.group(2)} does not exist"
            assert page in runner.read_text(), f"{mark.group(2)} does not run {page}"


@pytest.mark.parametrize("page,index,code", RUN_HERE, ids=[f"{p}:{i}" for p, i, _ in RUN_HERE])
def test_docs_block_runs(page, index, code, capsys):
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        exec(compile(code, f"{page} block {index}", "exec"), {"__name__": "__main__"})
    finally:
        os.chdir(cwd)
    assert capsys.readouterr().out  # each block prints what it shows
