"""resources/ and ui/ ship inside the wheel and are found from an installed package."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(out),
         str(ROOT)],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    (path,) = out.glob("fha_studio-*.whl")
    return path


def test_wheel_holds_every_resource_and_form(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for folder in ("resources", "ui"):
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and "__pycache__" not in path.parts:
                rel = path.relative_to(ROOT).as_posix()
                assert f"fha_studio/{rel}" in names, f"{rel} is not in the wheel"


def test_installed_wheel_finds_its_resources(wheel, tmp_path):
    # Unpack the wheel into a bare directory and import from there only, away from the checkout.
    target = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(target)
    script = (
        "import sys; sys.path.insert(0, sys.argv[1]);"
        "import fha_studio.paths as p;"
        "print(p.resources_dir()); print(p.ui_dir())"
    )
    result = subprocess.run([sys.executable, "-S", "-c", script, str(target)], capture_output=True, text=True,
                            cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    resources, ui = result.stdout.split()
    assert Path(resources) == target / "fha_studio" / "resources"
    assert Path(ui) == target / "fha_studio" / "ui"
