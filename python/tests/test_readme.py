"""python/README.md's example, and every python block of the book (docs/**/*.md), pass
`mypy --strict` as written (the names they import are re-exported by `limber`, every call
they make is typed). cli/tests/readme.rs counts on it for the book's python blocks."""

import os
import re
import subprocess
import sys

import pytest

from test_client import REPO


def python_blocks(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"```python\n(.*?)```", text, re.S)


def readme_python_blocks():
    return python_blocks(os.path.join(REPO, "python", "README.md"))


def docs_python_blocks():
    """(page, block) of every python block under docs/."""
    out = []
    for root, _, files in os.walk(os.path.join(REPO, "docs")):
        for name in sorted(files):
            if name.endswith(".md"):
                page = os.path.join(root, name)
                out.extend((os.path.relpath(page, REPO), b) for b in python_blocks(page))
    return out


def test_the_readme_example_passes_mypy_strict(tmp_path):
    blocks = readme_python_blocks()
    assert blocks, "python/README.md has no python block"
    check_mypy_strict(tmp_path, blocks)


def test_the_books_python_blocks_pass_mypy_strict(tmp_path):
    blocks = docs_python_blocks()
    assert blocks, "docs/ has no python block (docs/guide/python.md has one)"
    check_mypy_strict(tmp_path, [b for _, b in blocks])


def check_mypy_strict(tmp_path, blocks):
    try:
        import mypy  # noqa: F401
    except ImportError:
        msg = f"mypy is not installed in {sys.executable}"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)
    for i, block in enumerate(blocks):
        path = tmp_path / f"readme_{i}.py"
        path.write_text(block)
        out = subprocess.run(
            [sys.executable, "-m", "mypy", "--strict", "--no-incremental", str(path)],
            env=dict(os.environ, MYPYPATH=os.path.join(REPO, "python")), cwd=str(tmp_path),
            capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, f"block {i}:\n{block}\n{out.stdout}{out.stderr}"
