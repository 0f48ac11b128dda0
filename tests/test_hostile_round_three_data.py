"""Hostile input, round three, on the data side: result files out of range, the README generator's write
failures, and the smaller configs and files (a NaN signal probability, a stray sample name, a fast sample of
51 steps, limited supervision without a paired signal, PTAE's default width). Each test feeds one input that
was used silently or ended in a raw traceback, and checks the one sentence it now gets (or that it now works)."""
from __future__ import annotations

import builtins
import errno
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from pgae_lite.data.dataset import DataFormatError
from pgae_lite.data.original import load_original
from pgae_lite.runs import results
from pgae_lite.runs.result_checks import LARGEST, MEASURES
from pgae_lite.util.errors import PGAELiteError

ROOT = Path(__file__).resolve().parent.parent
TABLE1 = ROOT / "results" / "table1-original.json"


# --------------------------------------------------------------------------- result files out of range
def _table1(tmp_path, monkeypatch, change) -> None:
    """The committed Table 1 result changed by ``change`` (edits it, or returns the file's text), read from a
    results folder of its own."""
    result = json.loads(TABLE1.read_text())
    text = change(result)
    (tmp_path / "table1-original.json").write_text(text if isinstance(text, str) else json.dumps(result))
    monkeypatch.setenv(results.RESULTS_ENV, str(tmp_path))


def _pgae(result) -> dict:
    return result["data"]["rows"]["PGAE"]


@pytest.mark.parametrize("change, says", [
    (lambda r: _pgae(r)["stats"]["describe"]["accuracy"].update(median=250.0),
     r"table1-original.json: rows\['PGAE'\] describe accuracy median must be a finite number in \[0, 100\] "
     r"\(an accuracy"),
    (lambda r: _pgae(r)["stats"]["execute"]["nrmse"].update(median=-5.0),
     r"rows\['PGAE'\] execute nrmse median must be a finite number in \[0, 100\] \(an nRMSE in %"),
    (lambda r: _pgae(r)["seeds"]["1"]["repeat action"].update(nrmse=140.0),
     r"\['seeds'\]\['1'\]\['repeat action'\]\['nrmse'\] must be a finite number in \[0, 100\] \(an nRMSE"),
    (lambda r: _pgae(r)["paper"].update(describe=[193.05, 0.41]), r"describe accuracy paper must be .* \[0, 100\]"),
    (lambda r: json.dumps(r).replace('"median": 100.0', '"median": 1' + "0" * 308, 1),
     r"must be a finite number in \[0, 100\] \(an accuracy or a share in %\); got 1000"),  # a 309-digit accuracy
    (lambda r: _pgae(r)["seeds"]["0"]["describe"].update(nrmse_padded=-1.0),  # not in the table, yet in the file
     r"table1-original.json\['data'\]\['rows'\]\['PGAE'\]\['seeds'\]\['0'\]\['describe'\]\['nrmse_padded'\] must"),
    (lambda r: r.update(seconds=float("1" + "0" * 308)), r"\['seconds'\] must be a finite number of a size of at most"),
    (lambda r: json.dumps(r).replace('"seconds": ', '"seconds": NaN, "x": ', 1), r"\['seconds'\] must be a finite"),
    (lambda r: json.dumps(r).replace('"seconds": ', '"seconds": 1' + "0" * 5000 + ', "x": ', 1),
     "holds a number of thousands of digits"),
])
def test_a_figure_out_of_its_range_never_reaches_the_readme(tmp_path, monkeypatch, change, says):
    _table1(tmp_path, monkeypatch, change)
    with pytest.raises(results.ResultFileError, match=says):
        results.headline_table()


@pytest.mark.parametrize("data, keys, says", [
    ({"closed_loop": {"open_success_%": 250.0}}, ("closed_loop",), r"\['open_success_%'\] .* \[0, 100\] \(an accur"),
    ({"runs": [{"table1": {"describe": {"accuracy": -3.0}}}]}, ("runs",), r"\['accuracy'\] .* \[0, 100\]"),
    ({"cells": {"open nRMSE %": 101.0}}, ("cells",), r"\['open nRMSE %'\] .* \(an nRMSE in %"),
    ({"bytes": 10 ** 308}, ("bytes",), "of a size of at most 1e"),
    ({"seconds": 12.5, "rate": float("inf")}, ("seconds",), r"\['rate'\] must be a finite number"),
])
def test_the_books_reads_are_range_checked_too(tmp_path, monkeypatch, data, keys, says):
    """What a chapter quotes (results.value, results.load) passes the same checks, naming file, key path, range."""
    (tmp_path / "hostile.json").write_text(json.dumps({"data": data}))
    monkeypatch.setenv(results.RESULTS_ENV, str(tmp_path))
    for read in (lambda: results.value("hostile", *keys), lambda: results.load("hostile")):
        with pytest.raises(results.ResultFileError, match=r"hostile\.json\['data'\].*" + says):
            read()


def test_every_committed_result_file_is_in_range_and_the_bounds_are_stated():
    for name in results.names():
        results.load(name)                                              # every number checked
    assert LARGEST == 1e12 and [(m[0], m[2], m[3]) for m in MEASURES] == [("nrmse", 0, 100), ("accuracy", 0, 100)]
    assert results.readme_with_headline((ROOT / "README.md").read_text()) == (ROOT / "README.md").read_text()


# --------------------------------------------------------------------------- the README generator's write failures
@pytest.fixture
def repository(tmp_path, monkeypatch) -> Path:
    """A repository of its own: results/table1-original.json and a README whose headline is stale."""
    (tmp_path / "results").mkdir()
    shutil.copy(TABLE1, tmp_path / "results")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    start, end = readme.index(results.README_START), readme.index(results.README_END)
    (tmp_path / "README.md").write_text(readme[:start] + results.README_START + " old -->\nstale\n" + readme[end:])
    monkeypatch.delenv(results.RESULTS_ENV, raising=False)
    monkeypatch.setenv(results.REPOSITORY_ENV, str(tmp_path))          # restored after the test
    return tmp_path


def _one_sentence_and_unchanged(capsys, root: Path, before: str, says: str) -> None:
    with pytest.raises(SystemExit) as done:
        results.main(["--readme", "--root", str(root)])
    err = capsys.readouterr().err
    assert done.value.code == 2 and "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("error: ") and says in err, err
    assert (root / "README.md").read_text(encoding="utf-8") == before
    assert not list(root.glob("README.md.*.tmp"))                      # nothing half-written left beside it


def test_a_readme_that_is_a_link_is_refused_and_its_target_untouched(repository, capsys, tmp_path_factory):
    elsewhere = tmp_path_factory.mktemp("elsewhere") / "README.md"
    (repository / "README.md").rename(elsewhere)
    (repository / "README.md").symlink_to(elsewhere)
    before = elsewhere.read_text(encoding="utf-8")
    with pytest.raises(PGAELiteError, match="README.md: it is a symbolic link"):
        results.write_readme(repository)
    _one_sentence_and_unchanged(capsys, repository, before, "is a symbolic link")
    assert (repository / "README.md").is_symlink() and elsewhere.read_text(encoding="utf-8") == before


def _failing_open(monkeypatch, code: int, at: str) -> None:
    """open() of a temporary file fails with ``code`` when it is opened (a read-only checkout) or written (a full
    disk); every other open is the real one."""
    real_open = builtins.open

    class Full:
        def __init__(self, f):
            self.f = f

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

        def write(self, text):
            raise OSError(code, "No space left on device")

    def fake_open(path, mode="r", *args, **kwargs):
        if str(path).endswith(".tmp") and "w" in mode:
            if at == "open":
                raise OSError(code, "Read-only file system" if code == errno.EROFS else "Permission denied")
            return Full(real_open(path, mode, *args, **kwargs))
        return real_open(path, mode, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", fake_open)


@pytest.mark.parametrize("code, at, says", [
    (errno.ENOSPC, "write", "the disk is full"),
    (errno.EROFS, "open", "Read-only file system"),
    (errno.EACCES, "open", "Permission denied"),
])
def test_a_full_disk_or_a_read_only_checkout_is_one_sentence_and_the_readme_stays(repository, capsys, monkeypatch,
                                                                                  code, at, says):
    before = (repository / "README.md").read_text(encoding="utf-8")
    _failing_open(monkeypatch, code, at)
    _one_sentence_and_unchanged(capsys, repository, before, f"cannot write {repository / 'README.md'}: {says}")


@pytest.mark.parametrize("damage, says", [
    (lambda readme: readme.unlink(), "no README to rewrite at"),
    (lambda readme: readme.write_bytes(bytes(range(128, 256))), "is not text (UTF-8)"),
    (lambda readme: readme.write_text("# PGAE\n"), "README.md: the README must hold one generated block"),
    (lambda readme: (readme.unlink(), readme.mkdir()), "no README to rewrite at"),
])
def test_a_missing_or_damaged_readme_is_one_sentence(repository, capsys, damage, says):
    readme = repository / "README.md"
    damage(readme)
    with pytest.raises(SystemExit) as done:
        results.main(["--readme", "--root", str(repository)])
    err = capsys.readouterr().err
    assert done.value.code == 2 and err.count("\n") == 1 and says in err, err


def test_the_generator_still_rewrites_a_writable_readme(repository, capsys):
    results.main(["--readme", "--root", str(repository)])
    assert "headline table rewritten" in capsys.readouterr().out
    assert results.headline_table() in (repository / "README.md").read_text(encoding="utf-8")


# --------------------------------------------------------------------------- configs
@pytest.mark.parametrize("probs", [(math.nan,) * 5, (0.5, 0.5, math.nan, 0.0, 0.0), (0.5, 0.5, math.inf, 0, 0),
                                   ("0.2",) * 5, 0.2, (True, False, False, False, False)])
def test_signal_probs_holding_nan_or_no_numbers_are_refused(probs):
    from pgae_lite.train.config import TrainConfig

    with pytest.raises(ValueError, match=r"signal_probs must be 5 non-negative numbers summing to 1 \(finite"):
        TrainConfig(signal_probs=probs)


@pytest.mark.parametrize("of", ["samples", "updates"])
def test_limited_supervision_without_a_paired_signal_is_refused_naming_them(of):
    from pgae_lite.train.config import TrainConfig
    from pgae_lite.train.supervision import SupervisionConfig

    with pytest.raises(ValueError, match=r"no weight to any of the signals describe, execute, repeat both "
                                         r"\(the paired ones\), so limited supervision would train on no paired"):
        TrainConfig(signal_probs=(0.0, 0.0, 0.5, 0.0, 0.5), supervision=SupervisionConfig(0.2, of=of))
    with pytest.raises(ValueError, match=r"repeat action, repeat language \(the unimodal ones\)"):
        TrainConfig(signal_probs=(0.5, 0.5, 0.0, 0.0, 0.0), supervision=SupervisionConfig(0.2, of=of))
    TrainConfig(signal_probs=(0.5, 0.0, 0.5, 0.0, 0.0), supervision=SupervisionConfig(0.2, of=of))   # one of each


def test_ptaes_default_width_is_divided_by_its_default_heads():
    from pgae_lite.model.build import build_model
    from pgae_lite.model.config import HIDDEN, ModelConfig
    from pgae_lite.model.ptae import PTAE, CrossmodalConfig

    cfg = ModelConfig(crossmodal=CrossmodalConfig())                   # was refused: 50 wide, 4 heads
    assert cfg.hidden == 128 and cfg.hidden % cfg.crossmodal.heads == 0 and ModelConfig().hidden == HIDDEN == 50
    assert isinstance(build_model(cfg), PTAE) and PTAE().cfg == cfg
    assert cfg.to_dict()["hidden"] == 128                             # a recipe saves the width itself
    with pytest.raises(ValueError, match="among 3 heads: hidden must be a multiple of heads, e.g. 129"):
        ModelConfig(crossmodal=CrossmodalConfig(heads=3))


# --------------------------------------------------------------------------- the authors' files
def _tree(tmp_path, numbers=(0, 80)) -> Path:
    from test_original import _fake_tree

    return _fake_tree(tmp_path, numbers=numbers)


@pytest.mark.parametrize("name", ["target_old.txt", "target 1.txt", "target1_0.txt", "targetREADME.txt",
                                  "target\u0661.txt"])
def test_a_stray_target_file_without_a_pattern_number_is_refused_naming_it(tmp_path, name):
    root = _tree(tmp_path)
    stray = root / "target" / "behavior_train" / "201207" / name
    shutil.copy(root / "target" / "behavior_train" / "201207" / "target000000.txt", stray)
    with pytest.raises(DataFormatError, match="is not a sample's file: the authors name each sample target<pattern"):
        load_original(root)
    stray.unlink()
    assert len(load_original(root)) == 2


@pytest.mark.parametrize("number, steps", [(80, 51), (80, 100), (0, 50), (0, 99)])
def test_a_sample_whose_length_is_not_its_speeds_is_refused_naming_the_file(tmp_path, number, steps):
    root = _tree(tmp_path)
    rng = np.random.default_rng(1)
    for sub, width in (("behavior", 5), ("vision", 30), ("vision_opp", 30)):
        split = "test" if number == 80 else "train"
        path = root / "target" / f"{sub}_{split}" / "201207" / f"target{number:06d}.txt"
        np.savetxt(path, rng.uniform(0, 1, (steps, width)), fmt="%.6f")
    speed, length = ("FAST", 50) if number == 80 else ("SLOW", 100)
    with pytest.raises(DataFormatError, match=rf"target{number:06d}.txt: pattern {number} is \w+-\w-{speed}, which "
                                              rf"the authors record in {length} steps .*; found {steps}"):
        load_original(root)
