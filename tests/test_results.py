"""Results are data: every committed result file is complete, and every quote of one agrees with it.

The drift test: the README's headline table must be what ``python -m pgae_lite.runs.results
--readme`` writes from results/table1-original.json today; every figure a chapter or
the introduction quotes goes through ``pgae_lite.runs.results`` (``results.quote(...)`` in
a code cell, shown with glue), and every such quote must resolve in its file.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pgae_lite.runs import results

ROOT = Path(__file__).resolve().parent.parent
QUOTE = re.compile(r"results\.(?:quote|value)\(\s*([\"'][^)]*)\)")


def test_every_result_file_says_how_it_was_made():
    assert results.names(), "no result files in results/"
    for name in results.names():
        r = results.load(name)
        missing = {"benchmark", "command", "commit", "date", "machine", "profile", "seeds", "data"} - set(r)
        assert not missing, f"results/{name}.json lacks {sorted(missing)}"
        assert r["command"].startswith("python benchmarks/"), f"results/{name}.json: not made by a benchmark"
        assert re.fullmatch(r"[0-9a-f]{7,40}( \(\+ uncommitted changes\))?", r["commit"]), r["commit"]
        assert "cpu" in r["machine"] and "threads" in r["machine"]


def test_the_readme_headline_table_is_the_one_the_result_file_gives():
    readme = (ROOT / "README.md").read_text()
    assert results.readme_with_headline(readme) == readme, (
        "README.md's headline table differs from results/table1-original.json: "
        "run `python -m pgae_lite.runs.results --readme`")


def code_of(path: Path) -> str:
    """A notebook's code cells joined (a Markdown file: its text)."""
    if path.suffix != ".ipynb":
        return path.read_text()
    return "\n".join("".join(c["source"]) for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code")


def quotes_in(path: Path) -> list[tuple[str, ...]]:
    """The (name, key, ...) of every results.quote/value call in a notebook's code or a Markdown file."""
    found = []
    for args in QUOTE.findall(code_of(path)):
        keys = re.findall(r"[\"']([^\"']+)[\"']|(?<![\w.])(\d+)(?![\w.])", args.split("digits")[0])
        found.append(tuple(a or int(b) for a, b in keys))
    return found


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("*.ipynb")) + [ROOT / "book" / "intro.md"],
                         ids=lambda p: p.name)
def test_every_quoted_figure_is_in_its_result_file(path):
    for name, *keys in quotes_in(path):
        value = results.value(name, *keys)            # KeyError/FileNotFoundError if the quote has drifted
        if any(isinstance(k, str) and k in ("accuracy", "nrmse") for k in keys) or "%" in str(keys[-1:]):
            assert isinstance(value, (int, float)), f"{path.name}: {name} {keys} is not a number"


def test_quotes_are_found_by_the_drift_test():
    """The test above must see the quotes that the chapters make (it can fail)."""
    quoted = [q for p in sorted((ROOT / "notebooks").glob("*.ipynb")) for q in quotes_in(p)]
    assert quoted, "no chapter quotes a result file"
    with pytest.raises(KeyError, match="has no 'no such key'"):
        results.value(quoted[0][0], "no such key")


def test_a_missing_result_file_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv(results.RESULTS_ENV, str(tmp_path))
    with pytest.raises(FileNotFoundError, match="the result files are: none"):
        results.load("table1-original")


def write_ablations(folder: Path, recipe: list[float], changed: list[float]) -> None:
    """A minimal ablations result: describe accuracy per seed for the recipe and "concat"."""
    def cells(describe):
        return {"describe": {"accuracy": describe, "nrmse": 0.1}, "repeat language": {"accuracy": 100.0, "nrmse": 0.1},
                "execute": {"accuracy": 100.0, "nrmse": 0.4}, "repeat action": {"accuracy": 100.0, "nrmse": 0.4}}
    runs = [{"ablation": who, "seed": seed, "table1": cells(d)}
            for who, values in (("recipe", recipe), ("concat", changed)) for seed, d in enumerate(values)]
    (folder / "ablations.json").write_text(json.dumps({"data": {"runs": runs}}))


def test_an_ablation_is_judged_against_the_spread_of_the_seeds(tmp_path, monkeypatch):
    monkeypatch.setenv(results.RESULTS_ENV, str(tmp_path))
    write_ablations(tmp_path, recipe=[90.0, 94.0, 99.0], changed=[80.0, 85.0, 89.0])
    frame = results.ablation_frame("concat")
    assert frame.loc["describe accuracy %", "recipe (3 seeds)"] == "94.00 (90.00-99.00)"
    assert frame.loc["describe accuracy %", "beyond the seeds' spread"] == "yes, worse"
    assert frame.loc["execute nRMSE %", "beyond the seeds' spread"] == "no"
    assert results.ablation_verdict(frame) == "beyond the spread of the seeds: describe accuracy (worse)"
    write_ablations(tmp_path, recipe=[90.0, 94.0, 99.0], changed=[85.0, 91.0, 95.0])   # ranges overlap
    assert results.ablation_verdict(results.ablation_frame("concat")).startswith("no cell of Table 1 differs")
    with pytest.raises(KeyError, match="no ablation 'cells'; it has: concat"):
        results.ablation_frame("cells")


ABLATION_CALL = re.compile(r"ablation_frame\(\s*[\"']([\w-]+)[\"'](?:,\s*(?:name=)?[\"']([\w-]+)[\"'])?")


def test_every_ablation_a_chapter_quotes_is_in_its_result_file():
    calls = [c for p in sorted((ROOT / "notebooks").glob("*.ipynb")) for c in ABLATION_CALL.findall(code_of(p))]
    assert calls, "no chapter quotes the ablations"
    for ablation, name in calls:
        results.ablation_frame(ablation, name or "ablations")      # KeyError/FileNotFoundError if not


def test_the_repository_is_found_by_argument_variable_or_working_directory(tmp_path, monkeypatch):
    monkeypatch.delenv(results.REPOSITORY_ENV, raising=False)
    monkeypatch.delenv(results.RESULTS_ENV, raising=False)
    assert results.repository(ROOT) == ROOT                                   # an explicit argument
    monkeypatch.chdir(ROOT / "notebooks")                                     # where a chapter runs
    assert results.repository() == ROOT and results.results_dir() == ROOT / "results"
    monkeypatch.chdir(tmp_path)                                               # outside any repository
    with pytest.raises(results.RepositoryNotFoundError, match=f"at or above {tmp_path}.*set PGAE_LITE_REPOSITORY"):
        results.repository()
    monkeypatch.setenv(results.REPOSITORY_ENV, str(ROOT))                     # the variable
    assert results.repository() == ROOT and "table1-original" in results.names()
    with pytest.raises(results.RepositoryNotFoundError, match="root = .* holds no results/ folder"):
        results.repository(tmp_path)


def test_superseded_result_files_are_read_from_the_history_folder(monkeypatch):
    monkeypatch.delenv(results.RESULTS_ENV, raising=False)
    monkeypatch.chdir(ROOT)
    history = [n for n in results.names() if n.startswith("history/")]
    assert "history/fast-250x16-table1-original" in history
    assert results.measured(history[0]).startswith("measured ")


def test_the_readme_is_rewritten_in_a_repository_given_by_root(tmp_path):
    import shutil
    import subprocess
    import sys

    (tmp_path / "results").mkdir()
    shutil.copy(ROOT / "results" / "table1-original.json", tmp_path / "results")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    start, end = readme.index(results.README_START), readme.index(results.README_END)
    (tmp_path / "README.md").write_text(readme[:start] + results.README_START + " old -->\nstale\n" + readme[end:])
    done = subprocess.run([sys.executable, "-m", "pgae_lite.runs.results", "--readme", "--root", str(tmp_path)],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    written = (tmp_path / "README.md").read_text(encoding="utf-8")
    assert "stale" not in written and results.headline_table() in written
