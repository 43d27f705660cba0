"""The worked example of docs/python.md, run as written from a folder holding scenarios/."""
import os
import pathlib
import re

from conftest import SOURCE_DIR


def test_the_docs_example_runs_and_plots(tmp_path, monkeypatch, capsys):
    text = (SOURCE_DIR / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) == 1
    os.symlink(SOURCE_DIR / "scenarios", tmp_path / "scenarios")
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks[0], "docs/python.md", "exec"), {})
    png = pathlib.Path("quarter_car_sensitivity.png")
    assert png.stat().st_size > 10000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = capsys.readouterr().out
    assert re.search(r"comfort_rms = [0-9.e+-]+ m/s\^2", out), out
    assert "d/dvalve_current = " in out
