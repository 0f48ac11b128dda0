"""Hostile input to the data side: result files, dataset files, new colours, decoded words, the authors'
pattern files and a dataset without test samples. Each test is the reproduction of one input that was
used silently or ended in a raw traceback, and checks the one sentence it now gets."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

from pgae_lite.data.dataset import DataFormatError, PGAEDataset
from pgae_lite.runs import results
from pgae_lite.runs.rows import TABLE1_ROWS
from pgae_lite.world.words import LanguageError

ROOT = Path(__file__).resolve().parent.parent


# --------------------------------------------------------------------------- result files (README, book)
def _result(tmp_path, monkeypatch, change) -> Path:
    """The committed Table 1 result, changed by ``change`` (which edits it, or returns the file's text),
    written to a results folder of its own that the module then reads."""
    result = json.loads((ROOT / "results" / "table1-original.json").read_text())
    text = change(result)
    path = tmp_path / "table1-original.json"
    path.write_text(text if isinstance(text, str) else json.dumps(result))
    monkeypatch.setenv(results.RESULTS_ENV, str(tmp_path))
    return path


def _row(result) -> dict:
    return result["data"]["rows"]["PGAE"]


@pytest.mark.parametrize("change, says", [
    (lambda r: r["data"].update(rows=[1, 2]), "data.rows must be an object with one entry per row"),
    (lambda r: r["data"].pop("rows"), "data.rows must be an object"),
    (lambda r: r["data"].update(rows={}), "data.rows must be an object"),
    (lambda r: r["data"]["rows"].update(PGAE="fast"), r"rows\['PGAE'\] must be an object"),
    (lambda r: json.dumps(r).replace('"median": 100.0', '"median": 1' + "0" * 400, 1), "must be a finite number"),
    (lambda r: r.update(command="python x.py\u2028| injected |"), "command holds markup"),
    (lambda r: r.update(command="python x.py\x00"), "command holds markup"),
    (lambda r: r["machine"].update(cpu="[click](javascript:alert(1))"), "machine.cpu holds markup"),
    (lambda r: r["machine"].update(cpu="**AMD**"), "machine.cpu holds markup"),
    (lambda r: r["machine"].update(cores=-2), "machine.cores must be a whole number >= 1"),
    (lambda r: r["machine"].update(threads=2.5), "machine.threads must be a whole number >= 1"),
    (lambda r: r.update(date="yesterday"), "date must be an ISO date"),
])
def test_a_hostile_result_file_is_refused_before_the_headline_is_rendered(tmp_path, monkeypatch, change, says):
    _result(tmp_path, monkeypatch, change)
    with pytest.raises(results.ResultFileError, match=says):
        results.headline_table()


def test_a_command_may_hold_what_renders_as_itself_in_its_code_span(tmp_path, monkeypatch):
    _result(tmp_path, monkeypatch, lambda r: r.update(command="python benchmarks/table1.py --rows a,b && echo *"))
    assert "`python benchmarks/table1.py --rows a,b && echo *`" in results.headline_table()


@pytest.mark.parametrize("change, call, says", [
    (lambda r: _row(r)["seeds"]["0"]["describe"].update(nrmse=float("nan")), results.table1_frame,
     r"rows\['PGAE'\] describe nrmse of a seed must be a finite number"),
    (lambda r: _row(r).update(seeds={}), results.table1_frame, "holds no seeds"),
    (lambda r: _row(r)["paper"].update(describe=[93.05]), results.table1_frame, "lacks the describe nrmse paper"),
    (lambda r: r["data"]["rows"].update({"X|<b>": _row(r)}), results.table1_frame, "is not a row of Table 1"),
    (lambda r: _row(r)["verdict"]["describe"].update(accuracy="yes"), results.table1_met,
     r"rows\['PGAE'\] verdict must map each signal to true or false"),
])
def test_the_books_table1_is_read_through_the_same_checks(tmp_path, monkeypatch, change, call, says):
    _result(tmp_path, monkeypatch, change)
    with pytest.raises(results.ResultFileError, match=says):
        call("table1-original")


def test_the_books_table1_of_the_committed_result_is_unchanged():
    frame = results.table1_frame("table1-original")
    assert frame.shape == (16, 8) and np.isfinite(frame.to_numpy(dtype=float)).all()
    assert results.table1_met("table1-original") == {row: True for row in TABLE1_ROWS}
    with pytest.raises(KeyError, match="has no row 'PGAE-X'; it has: PGAE, PGAE-BERT"):
        results.table1_frame("table1-original", ["PGAE-X"])


@pytest.mark.parametrize("block", [
    "{end}\n{start} -->\n",                                 # the end before the start
    "{start} -->\n{start} -->\nold\n{end}\n",               # two starts
    "{start} --> old {end}\n",                              # no line break inside
])
def test_a_readme_with_misplaced_markers_is_one_sentence(block):
    readme = "# PGAE\n" + block.format(start=results.README_START, end=results.README_END)
    with pytest.raises(ValueError, match="the README must hold one generated block"):
        results.readme_with_headline(readme)


def test_the_readme_command_prints_one_line_for_a_damaged_result_and_leaves_the_readme(tmp_path):
    (tmp_path / "results").mkdir()
    result = json.loads((ROOT / "results" / "table1-original.json").read_text())
    _row(result)["stats"]["describe"]["accuracy"]["median"] = float("nan")
    (tmp_path / "results" / "table1-original.json").write_text(json.dumps(result))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    (tmp_path / "README.md").write_text(readme, encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "pgae_lite.runs.results", "--readme", "--root", str(tmp_path)],
                          cwd=tmp_path, capture_output=True, text=True,
                          env={k: v for k, v in os.environ.items() if k != results.RESULTS_ENV})
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines() == [done.stderr.strip()]
    assert done.stderr.startswith("error: table1-original.json: rows['PGAE'] describe accuracy median must be")
    assert (tmp_path / "README.md").read_text(encoding="utf-8") == readme


def test_every_committed_result_file_passes_the_checks():
    for name in results.names():
        assert results.measured(name).startswith("measured ")
    assert results.readme_with_headline((ROOT / "README.md").read_text()) == (ROOT / "README.md").read_text()


# --------------------------------------------------------------------------- dataset files and the features cache
@pytest.mark.parametrize("change, says", [
    (lambda d: dict(is_test=d.is_test.astype(int)), "is_test must hold true or false"),
    (lambda d: dict(lengths=d.lengths * 5), "lengths must be from 1 to 100; found 250"),
    (lambda d: dict(lengths=d.lengths + 0.5), "lengths must hold whole numbers"),
    (lambda d: dict(joints=d.joints.astype(str)), "joints must hold numbers"),
    (lambda d: dict(descriptions=d.descriptions[:, :2]),
     r"descriptions must hold whole numbers of shape \(144, 8, 3\)"),
    (lambda d: dict(pattern=-d.pattern - 1), "pattern must be 0 or more"),
])
def test_a_dataset_file_is_checked_for_what_its_arrays_hold(tmp_path, toy, change, says):
    path = tmp_path / "data.npz"
    replace(toy, **change(toy)).save(path, fingerprint="configs")
    with pytest.raises(DataFormatError, match=f"data.npz: {says}"):
        PGAEDataset.load(path, fingerprint="configs")


def test_a_cached_file_with_the_right_stamp_but_an_integer_split_is_made_again(tmp_path, toy):
    # An integer is_test would select samples by index: split("test") took all 144 samples.
    from pgae_lite.runs.data import cached_dataset
    from pgae_lite.util.storage import config_digest

    configs = {"data": "the configs that make it"}
    path = tmp_path / "features.npz"
    replace(toy, is_test=toy.is_test.astype(int)).save(path, fingerprint=config_digest(configs))
    with pytest.warns(UserWarning, match="is_test must hold true or false of shape .*computing the features again"):
        data = cached_dataset(path, lambda: toy, configs, toy.source, [str(i) for i in toy.ids])
    assert data.is_test.dtype == bool and len(data.split("test")) == 36
    assert PGAEDataset.load(path, fingerprint=config_digest(configs)).is_test.dtype == bool   # saved again


# --------------------------------------------------------------------------- new colours
@pytest.mark.parametrize("rgba", ["abc", None, ("1", "0.5", "0.05", "1"), (True, 0.5, 0.05, 1.0), {"r": 1},
                                  (complex(1, 0), 0.5, 0.05, 1.0), (10 ** 400, 0.5, 0.05, 1.0),
                                  (float("nan"), 0.5, 0.05, 1.0), ((0.98,), 0.5, 0.05, 1.0)])
def test_with_colour_refuses_an_rgba_that_is_not_four_numbers(rgba):
    from pgae_lite.world.colours import with_colour

    with pytest.raises(ValueError, match="rgba of 'orange' must be 4 numbers in \\[0, 1\\] with alpha 1.0"):
        with_colour("orange", "amber", rgba)


def test_with_colour_refuses_partners_and_worlds_of_the_wrong_kind():
    from pgae_lite.exercises.world import check_colour
    from pgae_lite.world.colours import with_colour

    with pytest.raises(LanguageError, match="partners must be a list of colours of the world; got 'blue'"):
        with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0), partners="blue")
    with pytest.raises(TypeError, match="world must be a World"):
        with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0), world="the paper's")
    said = check_colour("orange", (0.98, 0.50, 0.05, 1.0), world="the paper's")
    assert not said and "world must be a World" in str(said)
    assert with_colour("orange", "amber", np.array([0.98, 0.50, 0.05, 1.0])).rgba["orange"] == (0.98, 0.5, 0.05, 1.0)


def test_with_colour_and_the_exercise_apply_one_rule():
    from pgae_lite.exercises.world import check_colour
    from pgae_lite.world.colours import with_colour

    orange = with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0))
    rng = np.random.default_rng(0)
    for world in (None, orange):
        for rgb in rng.uniform(0, 1, (400, 3)).round(2):
            rgba = (*map(float, rgb), 1.0)
            try:
                with_colour("pink", "rose", rgba, **({"world": world} if world else {}))
                accepted = True
            except ValueError:
                accepted = False
            assert accepted == bool(check_colour("pink", rgba, world=world)), (rgba, world)


# --------------------------------------------------------------------------- decoded words
def test_decode_refuses_complex_rows_in_one_sentence():
    from pgae_lite.world.words import decode

    with pytest.raises(LanguageError, match=r"got 2-D torch.complex64 of shape \(2, 23\)"):
        decode(torch.zeros(2, 23, dtype=torch.complex64))
    assert decode(torch.eye(23)[[14, 3, 0]]) == "push blue"               # valid input: as before


# --------------------------------------------------------------------------- the authors' pattern files
def _pattern_files(tmp_path, actions: list[str], arrangements: list[str]) -> Path:
    (tmp_path / "actions.txt").write_text("\n".join(actions) + "\n", encoding="utf-8")
    (tmp_path / "arrangements.txt").write_text("\n".join(arrangements) + "\n", encoding="utf-8")
    return tmp_path


def _world_lines() -> tuple[list[str], list[str]]:
    from pgae_lite.world.patterns import Pattern

    patterns = [Pattern.from_number(i) for i in range(144)]
    return ([f"{p.code:<23}{'test' if p.is_test else 'train'}" for p in patterns],
            [f"{p.left}+{p.right}" for p in patterns])


@pytest.mark.parametrize("change, says", [
    (lambda a, r: a.insert(1, ""), None),                                         # a blank line is skipped
    (lambda a, r: (a.insert(1, ""), a.__setitem__(2, "XYZZY train")),
     r"actions.txt, line 3: 'XYZZY train' is not an action of the world"),       # named by its line
    (lambda a, r: a.__setitem__(0, "PUSH-L-SLOW train extra"), "actions.txt, line 1: 'PUSH-L-SLOW train extra'"),
    (lambda a, r: a.__setitem__(0, "PULL-L-SLOW train"),
     "actions.txt, line 1: pattern 0 is 'PUSH-L-SLOW train red\\+blue' in the world"),
    (lambda a, r: a.__setitem__(2, "SLIDE-L-SLOW train"), "pattern 2 is 'SLIDE-L-SLOW test red\\+blue'"),
    (lambda a, r: r.__setitem__(0, "blue+red"), "the files say PUSH-L-SLOW train blue\\+red"),
    (lambda a, r: (a.append(a[0]), r.append(r[0])), "must have one line per pattern, at most 144; found 145"),
    (lambda a, r: r.pop(), "found 144 and 143"),
])
def test_the_authors_pattern_files_must_be_the_worlds_patterns(tmp_path, change, says):
    from pgae_lite.data.original import _read_patterns

    actions, arrangements = _world_lines()
    change(actions, arrangements)
    root = _pattern_files(tmp_path, actions, arrangements)
    if says is None:
        assert _read_patterns(root)[2] == ("SLIDE-L-SLOW", "red+blue", "test")
        return
    with pytest.raises(DataFormatError, match=says):
        _read_patterns(root)


def test_the_real_pattern_files_are_the_worlds(original_data):
    from pgae_lite.data.original import _read_patterns

    assert len(_read_patterns(original_data)) == 144


# --------------------------------------------------------------------------- a dataset without test samples
def test_trained_model_refuses_a_dataset_without_test_samples_before_training(toy_short, monkeypatch):
    from pgae_lite.config import get_profile
    from pgae_lite.runs import pipeline
    from pgae_lite.runs.rows import TRAININGS

    def never(*args, **kwargs):
        raise AssertionError("training started")

    monkeypatch.setattr(pipeline, "loaded", lambda *a, **k: toy_short.subset(~toy_short.is_test))
    monkeypatch.setattr("pgae_lite.train.loop.train", never)
    monkeypatch.setattr(pipeline, "run_sweep", never)
    smoke = get_profile("smoke")
    for training in (TRAININGS["PGAE"], TRAININGS["PRAE"]):
        with pytest.raises(DataFormatError, match="has no test samples"):
            pipeline.trained_model(training, smoke, progress=False)
    with pytest.raises(DataFormatError, match="has no test samples"):
        pipeline.trained_models([TRAININGS["PGAE"], TRAININGS["PGAE-BERT"]], smoke, device="cpu", progress=False,
                                workers=2)
