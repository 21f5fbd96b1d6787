"""The README's library quickstart runs as written (docs that cannot drift, STYLE.md 12)."""

import os
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_the_library_quickstart_runs(tmp_path):
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Quickstart: library", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S)
    assert code, "README.md: no python block under 'Quickstart: library'"
    (tmp_path / "fixtures").symlink_to(ROOT / "fixtures")
    script = tmp_path / "quickstart.py"
    script.write_text(code.group(1))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert (tmp_path / "house.hiper").is_dir()
