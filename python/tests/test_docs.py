"""The Python blocks of docs/python.md run as written (from the repository root)."""

import os
import re

import pytest

from conftest import ROOT

BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "python.md").read_text(), flags=re.S)


def test_the_page_has_python_blocks():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_docs_block_runs(index, capsys):
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        exec(compile(BLOCKS[index], f"docs/python.md block {index}", "exec"), {})
    finally:
        os.chdir(cwd)
    assert capsys.readouterr().out  # each block prints what it shows
