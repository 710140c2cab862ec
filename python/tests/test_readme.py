"""The README's Python example runs as written, from the repository's root."""

from __future__ import annotations

import re

import numpy as np
import pytest

from conftest import REPOSITORY


def test_readme_example_renders_the_cornell_box(monkeypatch: pytest.MonkeyPatch) -> None:
    readme = (REPOSITORY / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.DOTALL)
    assert len(blocks) == 1, "the README has one Python example"
    monkeypatch.chdir(REPOSITORY)
    namespace: dict[str, object] = {}
    exec(compile(blocks[0], "README.md", "exec"), namespace)
    image = namespace["image"]
    assert isinstance(image, np.ndarray)
    assert image.shape == (128, 128, 3) and image.dtype == np.float32
    assert np.isfinite(image).all() and image.mean() > 0.0
    assert namespace["stats"].stop == "completed"  # type: ignore[attr-defined]
