"""Measured results as data: the committed result files that the benchmarks write (``results/*.json``).

Every measured figure the book, the README and the notes quote (Table 1 of the
paper's Sec. 4 on both datasets, closed-loop success, times) is read from a
result file through this module, never typed by hand, so a quote cannot drift
from its measurement. A result file is written by one of the scripts in
``benchmarks/`` (``benchmarks/harness.py``) and says how it was made::

    {"benchmark": "table1", "command": "python benchmarks/table1.py ...", "commit": "1a2b3c4",
     "date": "2026-11-24T15:02:11+00:00", "machine": {...}, "profile": "book",
     "seeds": [0, 1, 2], "seconds": 1234.5, "data": {...}}

    >>> value("recipe_time", "recipes", "fast", "minutes")       # a figure
    >>> quote("recipe_time", "recipes", "fast", "minutes", digits=1)   # the same, as text
    >>> measured("recipe_time")                                   # when, where and how

The files are found in the repository (:func:`repository`: an explicit ``root``, else
``$PGAE_LITE_REPOSITORY``, else the first folder at or above the working directory that holds
``results/`` and ``_toc.yml``), never beside the package's source, which an installed package
does not have. Superseded files lie in ``results/history/`` and are named ``history/NAME``.

Every value read is checked before it is rendered (:mod:`pgae_lite.runs.result_checks`): text that
renders as itself, finite numbers of a sane size, each figure in its measure's range (an accuracy
in [0, 100], an nRMSE in [0, 100]); a failure is a
:class:`~pgae_lite.runs.result_checks.ResultFileError` naming the file and the key.
``python -m pgae_lite.runs.results --readme`` (:func:`write_readme`) rewrites the README's headline
table atomically; a failure to read or write it is one sentence and leaves the README as it was.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pandas as pd

from pgae_lite.runs.result_checks import ResultFileError, check_figures, count_of, number_of, seeds_of, text_of
from pgae_lite.runs.rows import TABLE1_ROWS
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import OutputError, atomic_write_text
from pgae_lite.world.words import TEST_SIGNALS

RESULTS_ENV = "PGAE_LITE_RESULTS"          # a results folder alone (tests)
REPOSITORY_ENV = "PGAE_LITE_REPOSITORY"    # the repository's root


class RepositoryNotFoundError(PGAELiteError, FileNotFoundError):
    """No repository (a folder holding ``results/`` and ``_toc.yml``) where it was looked for."""


def repository(root: str | Path | None = None) -> Path:
    """The repository's root: ``root``, else ``$PGAE_LITE_REPOSITORY``, else the first folder at or
    above the working directory that holds ``results/`` and ``_toc.yml``."""
    given = root if root is not None else os.environ.get(REPOSITORY_ENV)
    if given:
        path = Path(given).expanduser()
        if not (path / "results").is_dir():
            where = "root" if root is not None else f"${REPOSITORY_ENV}"
            raise RepositoryNotFoundError(f"{where} = {str(given)!r} holds no results/ folder; give the "
                                          "pgae_lite repository's root (the folder of README.md and results/)")
        return path
    here = Path.cwd().resolve()
    for folder in (here, *here.parents):
        if (folder / "results").is_dir() and (folder / "_toc.yml").is_file():
            return folder
    raise RepositoryNotFoundError(f"no pgae_lite repository (a folder with results/ and _toc.yml) at or above "
                                  f"{here}; run from inside the repository, or set {REPOSITORY_ENV} to its root")


def results_dir(root: str | Path | None = None) -> Path:
    """``$PGAE_LITE_RESULTS``, else the repository's ``results/`` (:func:`repository`)."""
    return Path(os.environ.get(RESULTS_ENV) or repository(root) / "results")


def names() -> list[str]:
    """The result files there, by name (``table1-original`` for ``results/table1-original.json``;
    ``history/NAME`` for a superseded one in ``results/history/``)."""
    folder = results_dir()
    return sorted(p.stem for p in folder.glob("*.json")) + \
        sorted(f"history/{p.stem}" for p in (folder / "history").glob("*.json"))


def _read(name: str) -> dict:
    """The whole result file ``results/<name>.json`` as written, checked to be a result file only."""
    path = results_dir() / f"{name}.json"
    if not path.is_file():
        raise FileNotFoundError(f"no result file {path}; the result files are: {', '.join(names()) or 'none'} "
                                f"(set {RESULTS_ENV} to the folder that holds them)")
    try:
        result = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ResultFileError(f"{path} is not text (UTF-8): a result file is JSON; write it again") from None
    except json.JSONDecodeError as e:
        raise ResultFileError(f"{path} is not valid JSON (line {e.lineno}, column {e.colno}: {e.msg}); "
                              "write it again with its benchmark") from None
    except ValueError:                                  # Python's limit on the digits of a whole number
        raise ResultFileError(f"{path} holds a number of thousands of digits, which no benchmark writes; "
                              "write it again with its benchmark") from None
    if not isinstance(result, dict) or not isinstance(result.get("data"), dict):
        raise ResultFileError(f"{path} is not a result file: it must be a JSON object with a 'data' object "
                              "(benchmarks/harness.py writes them)")
    return result


def load(name: str) -> dict:
    """The whole result file ``results/<name>.json``, every number in it finite, of a sane size and in its
    measure's range (:mod:`pgae_lite.runs.result_checks`)."""
    result = _read(name)
    check_figures(result, f"{name}.json")
    return result


def value(name: str, *keys: str | int):
    """One figure: ``load(name)["data"][keys[0]][keys[1]]...``; a wrong key names the ones there are."""
    node, where = load(name)["data"], f"{name}.json: data"
    for key in keys:
        try:
            node = node[key]
        except (KeyError, IndexError, TypeError):
            there = ", ".join(map(str, node)) if isinstance(node, dict) else f"{len(node)} items"
            raise KeyError(f"{where} has no {key!r}; it has: {there}") from None
        where += f"[{key!r}]"
    return node


def quote(name: str, *keys: str | int, digits: int = 2) -> str:
    """A figure as text, ``digits`` after the point, thousands separated (``"1,234.50"``)."""
    return f"{value(name, *keys):,.{digits}f}"


def measured(name: str) -> str:
    """When, where and how a result file was made, as one line of text."""
    r = load(name)
    m = r.get("machine", {})
    if not isinstance(m, dict):
        raise ResultFileError(f"{name}.json: machine must be an object; got {m!r:.60}")
    said = {key: count_of(m.get(key, "?"), f"{name}.json: machine.{key}")
            for key in ("cpu", "cores", "torch", "threads")}
    threads = m.get("threads", "?")
    where = f"{said['cpu']}, {said['cores']} cores, {said['threads']} thread{'' if threads == 1 else 's'}"
    if m.get("gpu"):
        where += f", {text_of(m['gpu'], f'{name}.json: machine.gpu')}"
    seeds = r.get("seeds")
    seeds = seeds if seeds is None else seeds_of(seeds, f"{name}.json: seeds")
    profile = r.get("profile") if r.get("profile") is None else text_of(r["profile"], f"{name}.json: profile")
    date = text_of(r.get("date"), f"{name}.json: date")
    if not re.match(r"\d{4}-\d{2}-\d{2}", date):
        raise ResultFileError(f"{name}.json: date must be an ISO date and time (2026-11-27T13:29:04+00:00); "
                              f"got {date!r:.60}")
    return (f"measured {date[:10]} at commit "
            f"{text_of(r.get('commit'), f'{name}.json: commit')} ({where}, torch {said['torch']}, "
            f"profile {profile}, seeds {seeds}) by `{text_of(r.get('command'), f'{name}.json: command', code=True)}`")


def table1_rows(name: str) -> dict[str, dict]:
    """The rows of a ``benchmarks/table1.py`` result, each one of :data:`~pgae_lite.runs.rows.TABLE1_ROWS`
    (each figure is checked where it is read, :func:`table1_frame`)."""
    data = _read(name)["data"].get("rows")
    if not isinstance(data, dict) or not data:
        raise ResultFileError(f"{name}.json: data.rows must be an object with one entry per row of Table 1 "
                              f"({', '.join(TABLE1_ROWS)}); got {data!r:.60}")
    for row, r in data.items():
        if row not in TABLE1_ROWS:
            raise ResultFileError(f"{name}.json: row {row!r:.60} is not a row of Table 1; the rows "
                                  f"are: {', '.join(TABLE1_ROWS)}")
        if not isinstance(r, dict):
            raise ResultFileError(f"{name}.json: rows[{row!r}] must be an object; got {r!r:.60}")
    return data


def _cell(name: str, row: str, r: dict, what: str, signal: str, key: str) -> float:
    """One figure of a Table 1 row: our median, the paper's, or the min or max over the seeds."""
    where, figure = f"{name}.json: rows[{row!r}]", f"{signal} {key} {what}"
    try:
        if what == "paper":
            return number_of(r["paper"][signal][0 if key == "accuracy" else 1], f"{where} {figure}", key)
        if what == "median":
            return number_of(r["stats"][signal][key]["median"], f"{where} {figure}", key)
        per_seed = [number_of(s[signal][key], f"{where} {signal} {key} of a seed", key) for s in r["seeds"].values()]
    except (KeyError, IndexError, TypeError, AttributeError):
        raise ResultFileError(f"{where} lacks the {figure}") from None
    if not per_seed:
        raise ResultFileError(f"{where} holds no seeds, so no {figure}")
    return min(per_seed) if what == "min" else max(per_seed)


def table1_frame(name: str, rows: list[str] | None = None) -> pd.DataFrame:
    """Table 1 from a ``benchmarks/table1.py`` result: per row, our median, min and max over seeds, the paper's.

    Columns are (signal, "accuracy %" or "nRMSE %"); each row of the paper is followed by
    ours: "median", "min", "max" (over seeds) and "paper".
    """
    data = table1_rows(name)
    unknown = [row for row in rows or [] if row not in data]
    if unknown:
        raise KeyError(f"{name}.json has no row {unknown[0]!r}; it has: {', '.join(data)}")
    out = {}
    for row in rows or list(data):
        for what in ("median", "min", "max", "paper"):
            out[(row, what)] = {(signal, label): _cell(name, row, data[row], what, signal, key)
                                for signal in TEST_SIGNALS
                                for key, label in (("accuracy", "accuracy %"), ("nrmse", "nRMSE %"))}
    frame = pd.DataFrame(out).T
    frame.columns = pd.MultiIndex.from_tuples(frame.columns)
    return frame


def table1_met(name: str) -> dict[str, bool]:
    """Per row of a ``table1.py`` result: is every median cell at or better than the paper's?"""
    met = {}
    for row, r in table1_rows(name).items():
        verdict = r.get("verdict")
        cells = [x for v in verdict.values() for x in v.values()] if isinstance(verdict, dict) and all(
            isinstance(v, dict) for v in verdict.values()) else []
        if not cells or not all(isinstance(x, bool) for x in cells):
            raise ResultFileError(f"{name}.json: rows[{row!r}] verdict must map each signal to true or false "
                                  f"per measure; got {verdict!r:.60}")
        met[row] = all(cells)
    return met


def headline_table() -> str:
    """The README's headline table (Markdown): Table 1's medians on the authors' data next to the paper's."""
    name = "table1-original"
    head = ("| row | describe % | repeat language % | execute nRMSE % | repeat action nRMSE % |\n"
            "|---|---|---|---|---|")
    lines = [head]
    for row, r in table1_rows(name).items():
        cells = [f"{_cell(name, row, r, 'median', signal, key):.{digits}f} "
                 f"({_cell(name, row, r, 'paper', signal, key):.2f})"
                 for signal, key, digits in (("describe", "accuracy", 2), ("repeat language", "accuracy", 2),
                                             ("execute", "nrmse", 3), ("repeat action", "nrmse", 3))]
        lines.append(f"| {row} | " + " | ".join(cells) + " |")
    seeds = seeds_of(load(name).get("seeds"), f"{name}.json: seeds")
    lines.append(f"\nMedian over seeds {', '.join(map(str, seeds))} (the paper's figure in brackets); "
                 f"{measured(name)}.")
    return "\n".join(lines)


#: the Table 1 cells an ablation is judged on, (signal, measure): all but the accuracies of execute and
#: repeat action, which only say that the model wrote <EOS> (100% in every run)
ABLATION_CELLS = (("describe", "accuracy"), ("repeat language", "accuracy"), ("describe", "nrmse"),
                  ("repeat language", "nrmse"), ("execute", "nrmse"), ("repeat action", "nrmse"))


def ablation_frame(ablation: str, name: str = "ablations") -> pd.DataFrame:
    """One of chapter 04's ablations against the recipe, from a ``benchmarks/ablations.py`` result.

    Per Table 1 cell: the recipe's and the ablation's median over the seeds with their range
    (min-max), and whether the two ranges are apart, i.e. whether the effect exceeds the
    spread of the seeds ("yes, better" / "yes, worse" / "no").
    """
    runs = value(name, "runs")
    there = sorted({r["ablation"] for r in runs} - {"recipe"})
    if ablation not in there:
        raise KeyError(f"{name}.json has no ablation {ablation!r}; it has: {', '.join(there)}")

    def per_seed(who: str, signal: str, key: str) -> list[float]:
        return sorted(r["table1"][signal][key] for r in runs if r["ablation"] == who)

    def text(values: list[float], digits: int) -> str:
        return f"{pd.Series(values).median():.{digits}f} ({values[0]:.{digits}f}-{values[-1]:.{digits}f})"

    rows = {}
    for signal, key in ABLATION_CELLS:
        base, changed = per_seed("recipe", signal, key), per_seed(ablation, signal, key)
        digits = 2 if key == "accuracy" else 3
        higher = pd.Series(changed).median() > pd.Series(base).median()
        better = higher if key == "accuracy" else not higher
        apart = changed[0] > base[-1] or changed[-1] < base[0]
        rows[f"{signal} {'accuracy' if key == 'accuracy' else 'nRMSE'} %"] = {
            f"recipe ({len(base)} seeds)": text(base, digits),
            f"{ablation} ({len(changed)} seeds)": text(changed, digits),
            "beyond the seeds' spread": ("yes, better" if better else "yes, worse") if apart else "no"}
    return pd.DataFrame(rows).T


def ablation_verdict(frame: pd.DataFrame) -> str:
    """In one sentence: which cells of an :func:`ablation_frame` differ beyond the spread of the seeds."""
    verdicts = frame["beyond the seeds' spread"]
    apart = [f"{cell.removesuffix(' %')} ({v.removeprefix('yes, ')})" for cell, v in verdicts.items() if v != "no"]
    if not apart:
        return "no cell of Table 1 differs from the recipe's by more than the spread of the seeds"
    return "beyond the spread of the seeds: " + ", ".join(apart)


README_START, README_END = "<!-- headline:start", "<!-- headline:end -->"


def readme_with_headline(readme: str) -> str:
    """``readme`` (the README's text) with its generated block replaced by :func:`headline_table`."""
    starts, ends = readme.count(README_START), readme.count(README_END)
    if starts != 1 or ends != 1 or readme.index(README_END) < readme.index(README_START) or \
            "\n" not in readme.split(README_START, 1)[1].split(README_END, 1)[0]:
        raise ValueError(f"the README must hold one generated block, {README_START} ... -->, a line break, then "
                         f"{README_END}; found {starts} start and {ends} end markers")
    head, rest = readme.split(README_START, 1)
    first_line, _ = rest.split("\n", 1)
    _, tail = rest.split(README_END, 1)
    return f"{head}{README_START}{first_line}\n{headline_table()}\n{README_END}{tail}"


def write_readme(root: str | Path | None = None) -> Path:
    """Rewrite the repository's README.md with :func:`readme_with_headline`, atomically; every failure (a damaged
    result file or README, a README that is a link, a full disk, a read-only checkout) is one sentence (a
    :class:`~pgae_lite.util.errors.PGAELiteError`; misplaced markers, a ValueError) and leaves the README as it was."""
    readme = repository(root) / "README.md"
    if readme.is_symlink():                             # a write never goes through a link
        raise OutputError(f"refusing to rewrite {readme}: it is a symbolic link (to {os.readlink(readme)}); "
                          "put the README itself in its place")
    if not readme.is_file():
        raise OutputError(f"no README to rewrite at {readme}: the headline table is written into the "
                          "repository's README.md, which must exist")
    try:
        text = readme_with_headline(readme.read_text(encoding="utf-8"))
    except PGAELiteError:                               # a damaged result file: its own sentence
        raise
    except UnicodeDecodeError:
        raise OutputError(f"{readme} is not text (UTF-8); restore it from the repository") from None
    except OSError as e:
        raise OutputError(f"cannot read {readme}: {e.strerror or e}; the README is unchanged") from None
    except ValueError as e:                             # misplaced markers: say which file
        raise ValueError(f"{readme}: {e}") from None
    atomic_write_text(readme, text)                     # OutputError, and the old file whole, if it fails
    return readme


def main(argv: list[str] | None = None) -> None:
    """``python -m pgae_lite.runs.results --readme``: rewrite README.md's headline table; an error is one line."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m pgae_lite.runs.results",
                                     description="Rewrite README.md's headline table from the result file.")
    parser.add_argument("--readme", action="store_true", required=True, help="rewrite the README's headline table")
    parser.add_argument("--root", default=None, help=f"the repository (default: ${REPOSITORY_ENV}, else the "
                                                     "folder at or above here with results/ and _toc.yml)")
    args = parser.parse_args(argv)
    try:
        root = repository(args.root)
        os.environ[REPOSITORY_ENV] = str(root)          # every file below is read from this repository
        readme = write_readme(root)
    except (PGAELiteError, ValueError, OSError) as e:   # a damaged file, README or disk: one line, no traceback
        parser.exit(2, f"error: {e}\n")
    print(f"{readme}: headline table rewritten from {results_dir() / 'table1-original.json'}")


if __name__ == "__main__":
    main()
