"""No dead links: every link to the repository comes from one value, _config.yml's repository.url.

Unset (as committed), no button and no install cell points anywhere; set, all point there. The built
book's pages are checked by tests/test_book_browser.py (no launch or repository button while unset).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "book" / "_ext"))

from repository_links import BUTTONS, fill_in, theme_options  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
URL = "https://example.org/somebody/pgae_lite"


def _install_cell(path: Path) -> str:
    first = json.loads(path.read_text(encoding="utf-8"))["cells"][0]
    return "".join(first["source"]) if "google.colab" in "".join(first["source"]) else ""


def test_the_address_is_one_value_and_unset():
    config = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))
    assert config["repository"]["url"] == ""
    committed = "\n".join(p.read_text(encoding="utf-8") for p in NOTEBOOKS)
    assert "git+http" not in committed and "pgae-lite/pgae_lite" not in committed


def test_unset_no_button_points_anywhere():
    options = theme_options({"repository_url": "", "use_repository_button": True, "use_issues_button": True,
                             "launch_buttons": {"colab_url": "https://colab.research.google.com"}})
    assert "launch_buttons" not in options and "repository_url" not in options
    assert all(options[b] is False for b in BUTTONS)


def test_set_every_button_points_there():
    given = {"repository_url": URL, "use_repository_button": False,
             "launch_buttons": {"colab_url": "https://colab.research.google.com"}}
    options = theme_options(given)
    assert options["repository_url"] == URL and options["launch_buttons"] == given["launch_buttons"]
    assert options["use_repository_button"] is True and options["use_issues_button"] is True


def test_every_chapter_installs_from_the_address_the_build_fills_in():
    cells = {p.name: _install_cell(p) for p in NOTEBOOKS if _install_cell(p)}
    assert len(cells) >= 10
    for name, cell in cells.items():
        assert 'REPOSITORY = ""' in cell, name
        filled = json.loads(fill_in((ROOT / "notebooks" / name).read_text(encoding="utf-8"), URL))
        source = "".join(filled["cells"][0]["source"])
        assert f'REPOSITORY = "{URL}"' in source
        compile(source, name, "exec")                         # still Python
        namespace = {}
        exec(source.replace('"google.colab" in sys.modules', "False"), namespace)   # elsewhere: nothing happens
        assert namespace["REPOSITORY"] == URL
