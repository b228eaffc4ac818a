"""python/README.md's example passes `mypy --strict` as written (the names it imports are
re-exported by `limber`, every call it makes is typed)."""

import os
import re
import subprocess
import sys

import pytest

from test_client import REPO


def readme_python_blocks():
    with open(os.path.join(REPO, "python", "README.md"), encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"```python\n(.*?)```", text, re.S)


def test_the_readme_example_passes_mypy_strict(tmp_path):
    blocks = readme_python_blocks()
    assert blocks, "python/README.md has no python block"
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
