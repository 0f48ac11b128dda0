"""One map of the package: ``pgae_lite/__init__.py`` lists the top-level folders and modules in the
book's order, each folder's ``__init__`` lists its modules, and the book's reference page
(``book/api.md``) is made from those lists, so the three cannot drift apart.

After adding, moving or removing a module, update the lists and write the page again:
``python tests/test_package_map.py``.
"""
from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "pgae_lite"
API_PAGE = ROOT / "book" / "api.md"

INTRO = """# The package, folder by folder

Every chapter imports its plumbing from `pgae_lite`, and this page lists what
the package offers, folder by folder in the order the book introduces it (the
list of `pgae_lite/__init__.py`, below). Each entry is the docstring of the
code itself, so it cannot drift from what runs. Signatures are shown without
their type hints; the source, one click away (`[source]`), has them. The
command line is `python -m pgae_lite --help`.

```{eval-rst}
.. automodule:: pgae_lite
```
"""


def listed(init: Path) -> list[tuple[str, str]]:
    """The ``- ``name``  what it is`` entries of a package's docstring: (name, description), in order."""
    doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
    entries = []
    for line in doc.splitlines():
        if not line.startswith("- ``"):
            continue
        names, _, what = line[2:].partition("  ")       # "``a``, ``b``  what they are"
        for name in re.findall(r"``(\w+)``", names):
            entries.append((name, what.strip()))
    return entries


def top_entries() -> list[str]:
    """The package's top-level folders (with an ``__init__.py``) and modules, ``__init__`` aside."""
    return sorted(p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
                  if (p.suffix == ".py" and p.name != "__init__.py") or (p / "__init__.py").exists())


def folder_modules(folder: str) -> list[str]:
    """The modules of ``pgae_lite/folder`` and its subfolders that are packages (``course/labs``)."""
    path = PACKAGE / folder
    return sorted([p.stem for p in path.glob("*.py") if not p.name.startswith("_")]
                  + [p.name for p in path.iterdir() if (p / "__init__.py").is_file()])


def automodules(package: str) -> list[str]:
    """The ``automodule`` lines of a package's listed modules, a listed subpackage's own modules after it."""
    lines = []
    for module, _ in listed(PACKAGE / package / "__init__.py"):
        dotted = f"pgae_lite.{package}.{module}".replace("/", ".")
        lines.append(f"\n.. automodule:: {dotted}\n   :members:\n")
        if (PACKAGE / package / module / "__init__.py").is_file():
            lines += automodules(f"{package}/{module}")
    return lines


def api_page() -> str:
    """``book/api.md`` as the lists make it: a section per top-level entry, a module per listed name."""
    parts = [INTRO]
    for name, what in listed(PACKAGE / "__init__.py"):
        if name == "__main__":
            continue
        what = what.split(" (chapter")[0].split(": ")[0]
        parts.append(f"\n## `{name}`: {what}\n\n```{{eval-rst}}\n")
        if (PACKAGE / name).is_dir():
            parts.append(f".. automodule:: pgae_lite.{name}\n")
            parts += automodules(name)
        else:
            parts.append(f".. automodule:: pgae_lite.{name}\n   :members:\n")
        parts.append("```\n")
    return "".join(parts)


def test_the_package_lists_every_top_level_entry_once():
    names = [name for name, _ in listed(PACKAGE / "__init__.py")]
    assert len(names) == len(set(names)), names
    assert sorted(names) == top_entries(), "pgae_lite/__init__.py's list and the package's entries differ"


def test_every_folder_lists_its_modules():
    folders = [n for n in top_entries() if (PACKAGE / n).is_dir()]
    folders += [f"{n}/{p.name}" for n in folders for p in (PACKAGE / n).iterdir() if (p / "__init__.py").is_file()]
    for folder in folders:
        names = [name for name, _ in listed(PACKAGE / folder / "__init__.py")]
        assert sorted(names) == folder_modules(folder), f"pgae_lite/{folder}/__init__.py's list is not its modules"


def test_the_reference_page_is_made_from_the_lists():
    assert API_PAGE.read_text(encoding="utf-8") == api_page(), \
        "book/api.md differs from the package's lists: run `python tests/test_package_map.py` to write it again"


if __name__ == "__main__":
    API_PAGE.write_text(api_page(), encoding="utf-8")
    print(f"wrote {API_PAGE}", file=sys.stderr)
